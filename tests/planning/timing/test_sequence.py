"""planning.timing.sequence: a cycle of moves timed one after another — its duration is the moves' own
time_parameterize durations plus the dwells, its samples are each move's shifted in time with holds
between them, and bad dwells, gaps between moves and moves that do not move are refused."""
from __future__ import annotations

import numpy as np
import pytest

from planning.timing import TimingError, time_parameterize
from planning.timing.sequence import MAX_DWELL, time_sequence

V, A = np.array([1.0, 2.0]), np.array([3.0, 1.5])
P1 = np.array([[0.0, 0.0], [0.5, 0.2], [1.0, -0.3]])
P2 = np.array([[1.0, -0.3], [0.2, 0.4]])
P3 = np.array([[0.2, 0.4], [0.0, 0.0]])


def test_the_cycle_is_its_moves_and_dwells():
    dwells = [0.25, 0.0, 0.75]
    seq = time_sequence([P1, P2, P3], dwells, v_max=V, a_max=A)
    alone = [time_parameterize(P, V, A) for P in (P1, P2, P3)]
    assert seq.duration == pytest.approx(sum(tr.duration for tr in alone) + sum(dwells), rel=1e-12)
    assert np.allclose(seq.start, [0.0, alone[0].duration + 0.25, alone[0].duration + 0.25 + alone[1].duration])
    assert np.all(np.diff(seq.t) > 0) and seq.t[0] == 0 and seq.t[-1] == pytest.approx(seq.duration)
    # the first move's samples are its own; the second's are shifted by its start
    k = len(alone[0].t)
    assert np.array_equal(seq.q[:k], alone[0].q)
    assert np.allclose(seq.t[k:k + len(alone[1].t)], alone[1].t + seq.start[1])
    # the dwell after move 1: two samples at rest at the same configuration 0.25 s apart
    assert seq.t[k] - seq.t[k - 1] == pytest.approx(0.25)
    assert np.allclose(seq.q[k], seq.q[k - 1], rtol=0, atol=1e-12) and not seq.qd[k].any() and not seq.qd[k - 1].any()
    # no dwell after move 2: its last sample is move 3's first (not repeated)
    assert len(seq.t) == sum(len(tr.t) for tr in alone) - 1 + 1       # one shared sample, one final hold
    assert np.allclose(seq.q[-2:], P3[-1], rtol=0, atol=1e-12) and not seq.qd[-1].any()
    # within the limits at every sample
    assert np.all(np.abs(seq.qd) <= V * (1 + 1e-9)) and np.all(np.abs(seq.qdd) <= A * (1 + 1e-9))


@pytest.mark.parametrize("paths, dwells, words", [
    ([P1, P2], [0.0, -1.0], "move 2: dwell -1 s must be in"),
    ([P1, P2], [np.nan, 0.0], "move 1: dwell nan s"),
    ([P1, P2], [MAX_DWELL * 1.01, 0.0], "one day"),
    ([P1, P2], [0.0], "1 dwells for 2 moves"),
    ([P1, P3], [0.0, 0.0], r"move 2 starts 0.8 \(rad or m, joint 1\) away from where move 1 ends"),
    ([P1, np.array([[1.0, -0.3], [1.0, -0.3]])], [0.0, 0.0], "move 2 does not move"),
    ([P1[:1]], [0.0], "move 1: needs at least 2 configurations"),
    ([], [], "1 to 1000 moves"),
])
def test_bad_cycles_are_refused(paths, dwells, words):
    with pytest.raises(TimingError, match=words):
        time_sequence(paths, dwells, v_max=V, a_max=A)
