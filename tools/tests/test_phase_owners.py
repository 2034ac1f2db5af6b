"""The phase-owners table (chapters/README.md) follows a step's phases through the stepper's
classes: read on this tree's chapters, and on a made-up one where a derived chapter overrides
one phase's method."""
import pathlib
import textwrap

from femtools.docs import diffs, phase_owners

ROOT = pathlib.Path(__file__).resolve().parents[2]


def owners(root):
    dirs = diffs.chapter_dirs(root)
    info = phase_owners.classes(dirs)
    folders = {d.name[:2]: d for d in dirs}
    return {d.name[:2]: phase_owners.phase_owners(info, (d.name[:2], diffs.names(d)["class"]), folders)
            for d in dirs}


def test_the_course_phases_are_followed_to_the_chapter_that_overrides_them():
    found = owners(ROOT)
    assert found["01"]["solve"] == {"01": ["`step`"]}
    assert "dfdx" not in found["08"]  # the element pass does df/dx's work under forces
    assert found["08"]["constraints"]["07"] == ["`apply_constraints`"]
    assert "`element_pass`" in found["12"]["forces"]["12"]
    assert "`element_pass`" in found["11"]["forces"]["09"] and "12" not in found["11"]["forces"]
    assert "`solve_filtered_system`" in found["13"]["solve"]["13"]
    assert "its preconditioner" in found["12"]["solve"]["12"]


def test_a_derived_chapter_owns_the_phase_it_overrides(tmp_path):
    def write(path, text):
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text))
    write(tmp_path / "chapters/01_base/stepper.hpp", """\
        namespace fem::ch01 {
        class BaseStepper : public Stepper {
         public:
          void step(State& state) override;
         protected:
          virtual void solve();
        };
        }
        """)
    write(tmp_path / "chapters/01_base/stepper.cpp", """\
        void BaseStepper::step(State& state) {
          {
            // the forces
            PhaseTimer t(profile_.forces);
            forces(state);
          }
          {
            PhaseTimer t(profile_.solve);
            solve();
          }
        }
        void BaseStepper::solve() {}
        """)
    write(tmp_path / "chapters/02_derived/stepper.hpp", """\
        namespace fem::ch02 {
        class DerivedStepper final : public ch01::BaseStepper {
          void solve() override;
        };
        }
        """)
    write(tmp_path / "chapters/02_derived/stepper.cpp", "void DerivedStepper::solve() { ch01::helper(); }\n")
    found = owners(tmp_path)
    assert found["01"] == {"forces": {"01": ["`step`"]}, "solve": {"01": ["`step`", "`solve`"]}}
    assert found["02"]["forces"] == {"01": ["`step`"]}
    assert found["02"]["solve"] == {"01": ["`step`", "`helper`"], "02": ["`solve`"]}
