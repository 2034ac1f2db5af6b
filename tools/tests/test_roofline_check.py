"""The roofline plot's --check (femtools.plots.roofline.problems): a phase measured faster than
its bound is a broken model, whatever the phase (compose's zeroing of A is priced at its own roof:
no slack), and a level without one of the roofs a written byte is priced at is refused."""
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
    assert not check("solve", 1.0e-3, 0.99e-3, monkeypatch)


def test_compose_has_no_slack(monkeypatch):
    assert not hasattr(roofline, "MEMSET_SLACK")
    assert check("compose", 1.0e-3, 1.01e-3, monkeypatch)
    assert not check("compose", 1.0e-3, 1.0e-3, monkeypatch)


def test_a_level_without_its_update_or_zeroing_roof_is_refused():
    level = {"name": "L2", "read": 2e11, "write": 2.5e11, "update": 2.2e11, "zero": 2.5e11}
    data = {"roofs": [{"threads": 1, "levels": [level]}], "runs": []}
    assert not roofline.problems(data)
    for kind in ("update", "zero"):
        partial = {k: v for k, v in level.items() if k != kind}
        found = roofline.problems({"roofs": [{"threads": 1, "levels": [partial]}], "runs": []})
        assert found == [f"roofs at 1 thread(s): level L2 has no {kind} roof"]
