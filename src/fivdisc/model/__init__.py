"""The numerical model of a case: the annular plate and its modes, speed profiles,
and the arrays the compiled core reads."""
