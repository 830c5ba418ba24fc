"""The compiled core (C++, built at install): the non-smooth integrator, the right-hand
side and its complex step, the tangent dynamics (``_core``, sources in ``src/``)."""
