"""Chapter 14's layout rule against its lesson's rows (femtools.docs.layouts): the lines say, per
finest level and thread count, which layout measured faster in both kernels, and mark where it is
not the one the stepper runs."""
from femtools.docs import layouts

HEADER = ("| beam_50k.msh (41283 rows), finest level, float | threads | chapter 12, us | pair lanes, us "
          "| speedup | packed pairs, us | speedup |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: |\n")


def lesson(rows, runs="packed"):
    body = "".join(f"| {k} | {n} | 9 | {padded} | x1 | {packed} | x1 |\n" for k, n, padded, packed in rows)
    return {"table": HEADER + body + f"\nMedians. The stepper's V-cycle runs this level {runs} (it does not fit).\n"}


def test_the_faster_layout_per_thread_count_and_where_the_stepper_runs_the_other():
    record = lesson([("smoothing step", "1", 8.0, 7.0), ("residual", "1", 6.0, 5.0),
                     ("smoothing step", "2", 3.0, 4.0), ("residual", "2", 2.0, 3.0)])
    text = layouts.section(record, "X (2 cores), GNU 12, commit abc")
    assert ("- `beam_50k.msh`, which the stepper runs packed: at 1 thread the packed pairs are the faster; "
            "at 2 threads the padded pairs are the faster (**not** the stepper's).") in text
    assert "commit abc" in text


def test_kernels_that_disagree_name_neither():
    record = lesson([("smoothing step", "1", 8.0, 7.0), ("residual", "1", 5.0, 6.0)])
    assert "at 1 thread neither layout is the faster in both kernels." in layouts.section(record)
    assert layouts.section({"table": "| a |\n| --- |\n"}).startswith("*No finest level")
