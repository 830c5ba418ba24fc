"""Compiled kernels (numba). Importing the package keys their on-disk cache to the
sources of all of them (:mod:`fivdisc._kernels.cache`)."""

from fivdisc._kernels.cache import install

install()
