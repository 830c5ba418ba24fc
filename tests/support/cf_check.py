"""What every dataset fivdisc writes must satisfy (issue 12, item 3), checked with cf_xarray.

Imported by the tests of each output; not a test module itself.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

DOI = "10.1007/s11071-019-05168-x"


def check_cf(ds: xr.Dataset, group: bool = False) -> None:
    """Assert the CF metadata fivdisc promises on a dataset (or one group of a file).

    - global attributes Conventions (CF-1.x), title, institution, source (fivdisc and its
      version), history and references (the paper's DOI);
    - dimensions named after what they are: never x or y, and no dimension whose
      coordinate is all NaN (a placeholder);
    - every numeric variable and coordinate has units that parse (udunits syntax, through
      cf_xarray's pint registry) and a long_name; text variables have a long_name;
    - flag variables have as many meanings as values, and cf_xarray decodes them.
    """
    import cf_xarray  # noqa: F401  (registers the .cf accessor)
    from cf_xarray.units import units as registry

    attrs = ds.attrs
    assert attrs["Conventions"].startswith("CF-1."), attrs.get("Conventions")
    for key in ("title", "institution", "source", "history", "references"):
        assert str(attrs.get(key, "")).strip(), f"missing global attribute {key}"
    assert attrs["source"].startswith("fivdisc "), attrs["source"]
    assert DOI in attrs["references"]
    assert not {"x", "y", "curve"} & set(map(str, ds.dims)), list(ds.dims)
    for dim in ds.dims:
        if dim in ds.coords and ds[dim].dtype.kind == "f":
            assert np.isfinite(ds[dim].values).any(), f"dimension {dim} is a NaN placeholder"
    for name, var in ds.variables.items():
        assert str(var.attrs.get("long_name", "")).strip(), f"{name} has no long_name"
        if var.dtype.kind in "biuf":
            assert "units" in var.attrs, f"{name} has no units"
            registry.Unit(var.attrs["units"])  # raises if udunits would not parse it
        if "flag_values" in var.attrs:
            values = np.atleast_1d(var.attrs["flag_values"])
            meanings = var.attrs["flag_meanings"].split()
            assert len(values) == len(meanings), name
            first = meanings[0]
            np.testing.assert_array_equal((ds[name].cf == first).values,
                                          ds[name].values == values[0])
