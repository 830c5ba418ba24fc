"""Write ``three_pads.npz``: orbits of issue 36's three-pad case, the starts of the tests
of ``tests/continuation/test_several_pads.py`` (so that they need no 10 s transient).

Run ``python tests/data/make_three_pads.py`` (some minutes). Each entry ``NAME_state``,
``NAME_period``, ``NAME_phases``, ``NAME_speed`` is a converged orbit, found as the issue's
commands find it (``fivdisc orbit ... --transient 10``) and, for the speeds in between,
continued from there:

* ``S22``: the orbit at 22 rad/s, the pads sticking in turn (T/3 apart);
* ``S11.9``: that orbit continued to 11.9 rad/s, 0.06 above the border at 11.838233 where
  the pads' releases meet the next pads' sticks;
* ``A11.8``: the asymmetric orbit a 10 s transient finds at 11.8 rad/s (``ss-11.8``);
* ``P5.2``: the in-phase orbit a 15 s transient finds at 5 rad/s (``ss-5``), continued to
  5.2 rad/s;
* ``X8``: the last iterate of Newton shooting at 8 rad/s (``ss-8``, tolerance 1e-6),
  where the shooting map is discontinuous.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.case import Case
from fivdisc.continuation.walk import continue_orbit

CASE = Path(__file__).with_name("three_pads.toml")


def main() -> None:
    case = Case.from_toml(CASE.read_text(encoding="utf-8"))
    out: dict[str, np.ndarray] = {}

    def keep(name: str, state, period, phases, speed) -> None:
        out[f"{name}_state"] = np.asarray(state, dtype=float)
        out[f"{name}_period"] = np.float64(period)
        out[f"{name}_phases"] = np.asarray(phases, dtype=np.int64)
        out[f"{name}_speed"] = np.float64(speed)
        print(f"{name}: {speed} rad/s, T = {period!r} s")

    s22 = periodic_orbit(case, transient=10.0)
    keep("S22", s22.state, s22.period, s22.phases, 22.0)
    br = continue_orbit(case, "speed.value", 11.9, orbit=s22, max_points=60,
                        confirm_periods=0)
    assert br.stop_reason.startswith("reached"), br.stop_reason
    keep("S11.9", br.dataset["state"].values[-1], br.period[-1], br.phases(len(br) - 1),
         br.parameter[-1])
    ss118 = case.replace({"speed.value": 11.8})
    a = periodic_orbit(ss118, transient=10.0)
    keep("A11.8", a.state, a.period, a.phases, 11.8)
    ss5 = case.replace({"speed.value": 5.0})
    p5 = periodic_orbit(ss5, transient=15.0)
    br = continue_orbit(ss5, "speed.value", 5.2, orbit=p5, max_points=20, confirm_periods=0)
    assert br.stop_reason.startswith("reached"), br.stop_reason
    keep("P5.2", br.dataset["state"].values[-1], br.period[-1], br.phases(len(br) - 1),
         br.parameter[-1])
    ss8 = case.replace({"speed.value": 8.0})
    x8 = periodic_orbit(ss8, transient=10.0, tol=1e-6)
    keep("X8", x8.state, x8.period, x8.phases, 8.0)
    np.savez(Path(__file__).with_name("three_pads.npz"), **out)


if __name__ == "__main__":
    main()
