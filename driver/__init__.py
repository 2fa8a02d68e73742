"""Mechanism-analysis studies driven by namelist decks: ``python -m driver DECK``.

Studies (one module each, named after their namelist group) run Fortran 90
kernels through :mod:`driver.kernels` and write fixed-format tables with
:mod:`driver.table`, tidy tables with :mod:`driver.export` and figures with
:mod:`driver.plotting`.
"""
__version__ = "0.1.0"
