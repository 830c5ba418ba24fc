"""One event, one name (issue 40): a change of a branch's event signature is named by the
phase that is born, the shortest phase of the slider that changes on the side that has
it. The cycles here are made by hand: their events say which phase is short."""

from __future__ import annotations

import numpy as np
import pytest

from fivdisc import BifurcationKind
from fivdisc.analysis.cycle import Cycle
from fivdisc.continuation.detection import discontinuity_kind

PERIOD = 0.01


def _cycle(signature: str, events: list[tuple[float, str]]) -> Cycle:
    return Cycle((signature,), {}, np.array([t for t, _ in events]), np.ones(1, bool),
                 tuple((t, kind, 0) for t, kind in events), PERIOD)


SLIP_STICK = _cycle("slip+ > stick > slip+", [(0.002, "stick"), (0.006, "slip")])


@pytest.mark.parametrize(("before", "after", "kind", "words"), [
    # a stick phase of 1 us is born inside a slip: the slip speed touched zero
    (_cycle("slip+", []),
     _cycle("slip+ > stick > slip+", [(0.003, "stick"), (0.003001, "slip")]),
     BifurcationKind.GRAZING, "stick boundary"),
    # a slip of 1 us is born between two sticks: the stick margin touched zero
    (SLIP_STICK,
     _cycle("slip+ > stick > slip+ > stick > slip+",
            [(0.002, "stick"), (0.004, "slip"), (0.004001, "stick"), (0.006, "slip")]),
     BifurcationKind.STICK_SPLIT, "stick phase splits"),
    # a short flight: the normal force touched zero
    (SLIP_STICK,
     _cycle("slip+ > stick > slip+ > flight > slip+",
            [(0.002, "stick"), (0.006, "slip"), (0.008, "separation"),
             (0.008001, "recontact")]),
     BifurcationKind.GRAZING, "separation boundary"),
    # a slip reversal is born: no switching boundary is grazed by a phase of its own
    (SLIP_STICK,
     _cycle("slip+ > stick > slip- > slip+",
            [(0.002, "stick"), (0.006, "slip"), (0.0070, "reversal"), (0.007001, "reversal")]),
     BifurcationKind.SIGNATURE_CHANGE, ""),
])
def test_a_signature_change_is_named_by_the_phase_born(before, after, kind, words):
    found, text = discontinuity_kind(before, after)
    assert found == kind
    assert words in text
    # the same event seen from the other side (the phase vanishing) has the same name
    assert discontinuity_kind(after, before)[0] == kind


def test_phases_exchanged_are_a_signature_change():
    after = _cycle("slip- > stick > slip-", [(0.002, "stick"), (0.006, "reversal")])
    assert discontinuity_kind(SLIP_STICK, after)[0] == BifurcationKind.SIGNATURE_CHANGE
