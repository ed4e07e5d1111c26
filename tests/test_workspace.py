"""The memory the check reuses from take to take: lent to one check at a time, and bounded."""

import numpy as np

import motiontheater as mt
from motiontheater.databases import workspace
from motiontheater.databases.check import check_motion


def test_a_workspace_lends_the_same_memory_to_the_next_take_and_none_to_two_at_once():
    with workspace.lent() as space:
        first = space.array("positions", (10, 4, 3))
        first[:] = 1.0
        assert space.array("positions", (5, 3)).base is first.base  # a smaller take: the same memory
        with workspace.lent() as inner:  # a check inside a check: memory of its own
            assert not np.shares_memory(inner.array("positions", (10, 4, 3)), first)
        assert not np.shares_memory(space.array("world", (10, 3, 3)), first)
    with workspace.lent() as again:
        assert np.shares_memory(again.array("positions", (2, 4, 3)), first)


def test_a_workspace_keeps_no_more_than_its_bound():
    most = workspace.KEPT_BYTES // 8
    space = workspace.Workspace()
    kept = space.array("a", (most // 2,))
    assert np.shares_memory(space.array("a", (10,)), kept)
    large = space.array("b", (most // 2 + 1,))  # a and b together would pass the bound: b is not kept
    assert large.shape == (most // 2 + 1,)
    assert not np.shares_memory(space.array("b", (most // 2 + 1,)), large)


def test_a_take_checked_after_others_has_the_findings_it_has_alone(data_dir):
    """What a take before left in the workspace changes nothing: a take with a spike checked
    after a longer one (whose kinematics fill more of the memory) finds what it found first."""
    amc = data_dir / "cmu" / "01_01.amc"
    take = mt.read_amc(amc, mt.read_asf(mt.skeleton_path_for(amc)))
    values = take.values.copy()
    values[40, take.columns("rhumerus")[0]] += 90.0
    spiked = take.replace(values=values)
    alone = check_motion(spiked, "spiked")
    check_motion(take.replace(values=np.concatenate([take.values, take.values[::-1]])), "longer")
    assert any(f.kind == "spike" and f.first == 40 + take.first_frame for f in alone)
    assert check_motion(spiked, "spiked") == alone
