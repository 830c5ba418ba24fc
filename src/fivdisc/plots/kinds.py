"""The kinds of figure of a simulation result, kept apart from :mod:`fivdisc.plots` so that
the command line offers them (``fivdisc plot --kind``) without importing xarray and the
analyses that drawing them needs."""

#: The kinds of figure of a simulation result (``fivdisc plot --kind``).
KINDS = ("timeseries", "spectrogram", "spectrum", "phase", "friction", "normal-force")
