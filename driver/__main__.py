"""``python -m driver DECK ...``"""
import sys

from driver._cli import main

sys.exit(main())
