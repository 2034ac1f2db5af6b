"""The roofline plot's --check (femtools.plots.roofline.problems): a phase measured faster than
its bound is a broken model, but for compose, whose memset of A may beat the measured write roof
by up to MEMSET_SLACK (issue 56 prices such stores)."""
from femtools.plots import roofline


def data_with(phase, measured_s, bound_s):
    return {"roofs": [], "runs": [{"chapter": "12_half_the_bytes", "threads": 1,
                                   "mesh": "plate_poster.msh",
                                   "phases": [{"phase": phase, "measured_s": measured_s,
                                               "bound_s": bound_s}]}]}


def check(phase, measured_s, bound_s, monkeypatch):
    monkeypatch.setattr(roofline, "phase_problem", lambda p, with_waiting: None)
    return roofline.problems(data_with(phase, measured_s, bound_s))


def test_a_phase_faster_than_its_bound_is_refused(monkeypatch):
    assert check("solve", 1.0e-3, 1.01e-3, monkeypatch)


def test_compose_may_beat_its_bound_by_the_memset_slack_only(monkeypatch):
    assert not check("compose", 1.0e-3, 1.77e-3, monkeypatch)
    assert check("compose", 1.0e-3, 1.01e-3 * roofline.MEMSET_SLACK, monkeypatch)
