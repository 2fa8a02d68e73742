"""Type stub of driver/_version.py, which meson generates from driver/_version.py.in at build time."""
__version__: str
