"""Chapter 14's layouts against the lesson's own measurement: the stepper times its two layouts
of a finest level (padded and packed pairs, the same bits) in its first prepare on each
team size, in turn, and runs the one of the shorter median (lane_v_cycle.hpp). Whether that choice
gives the shorter whole step is a measurement, which can differ with the machine, the thread
count and the sitting, so the lines that say it are generated from the rows of `fem_lessons
every-lane` (docs/data/lessons/every-lane.json: whole steps in each layout, in turn), between the
markers every-lane-layouts of the chapter's README, by `fem-tools docs lessons`."""
import math
import re

MARKER = "every-lane-layouts"
KERNELS = ("smoothing step", "residual")
STEP = "one step"  # the row's name begins so: whole steps in each layout, what the choice is for
ROUNDS = re.compile(r"(\d+) rounds; packed shorter in (\d+)")  # the step row's pairs
SIGNIFICANCE = 0.05  # a sign test's two-sided p below it: the layouts', not the machine's
LAYOUTS = {"padded": "pair lanes, us", "packed": "packed pairs, us"}


def cells(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]


def levels(text):
    """Per finest level of the lesson's text: its mesh, the layout the stepper runs it in at each
    thread count ({threads: layout}, from the table's caption), {(kernel, threads): {layout:
    microseconds}} and {threads: (rounds, rounds the packed step was the shorter)}."""
    found, lines, i = [], text.split("\n"), 0
    while i < len(lines):
        if not (lines[i].startswith("|") and "finest level" in lines[i]):
            i += 1
            continue
        header = cells(lines[i])
        column = {name: header.index(title) for name, title in LAYOUTS.items() if title in header}
        times, pairs, i = {}, {}, i + 2
        while i < len(lines) and lines[i].startswith("|"):
            row = cells(lines[i])
            kind = STEP if row[0].startswith(STEP) else row[0]
            if kind == STEP and (counted := ROUNDS.search(row[0])):
                pairs[row[1]] = (int(counted.group(1)), int(counted.group(2)))
            if kind in KERNELS + (STEP,) and len(column) == len(LAYOUTS) and \
                    all(row[k] for k in column.values()):
                times[(kind, row[1])] = {name: float(row[k]) for name, k in column.items()}
            i += 1
        caption = next((line for line in lines[i:] if line.strip()), "")
        clause = re.search(r"runs this level ([^(;]*)", caption)
        runs = dict((n, layout) for layout, n in
                    re.findall(r"(padded|packed) at (\d+) threads?", clause.group(1) if clause else ""))
        found.append((header[0].split()[0], runs, times, pairs))
    return found


def faster(times, threads, kinds):
    """The layout faster in every row of those kinds at that thread count, else None."""
    winners = {min(t, key=t.get) for (kind, n), t in times.items() if n == threads and kind in kinds}
    return winners.pop() if len(winners) == 1 else None


def sign_test(rounds, wins):
    """Two-sided p of `wins` in `rounds` if either layout were as likely the shorter."""
    tail = min(wins, rounds - wins)
    return min(1.0, 2 * sum(math.comb(rounds, k) for k in range(tail + 1)) / 2 ** rounds)


def step_verdict(step, pairs):
    """(the layout of the shorter step, or None where the rounds cannot tell, and the words)."""
    best = min(step, key=step.get)
    apart = f"{100 * (max(step.values()) / step[best] - 1):.0f}%"
    if not pairs:
        return best, f"{best}'s steps shorter (medians {apart} apart)"
    rounds, packed = pairs
    if sign_test(rounds, packed) < SIGNIFICANCE:
        shorter = "packed" if 2 * packed > rounds else "padded"
        wins = packed if shorter == "packed" else rounds - packed
        return shorter, f"{shorter}'s steps shorter in {wins} of {rounds} rounds (medians {apart} apart)"
    return None, f"the steps undecided (packed's shorter in {packed} of {rounds} rounds, medians {apart} apart)"


def section(record, where=None):
    """One line per finest level: at each thread count the layout the stepper chose and the one
    of the shorter whole step in the lesson, where its rounds tell (a sign test), and the one
    faster in both kernels where they say otherwise (where: named by the table's own caption)."""
    lines = []
    for mesh, runs, times, pairs in levels(record.get("table", "")):
        threads = sorted({n for _, n in times}, key=int)
        if not runs or not threads:
            continue
        said = []
        for n in threads:
            chose, kernels = runs.get(n), faster(times, n, KERNELS)
            best, verdict = step_verdict(times[(STEP, n)], pairs.get(n)) if (STEP, n) in times \
                else (None, "no whole-step row")
            mark = "" if not best or not chose or best == chose else " (**not** the stepper's)"
            if best and kernels != best:
                verdict += f", {kernels} in both kernels" if kernels else ", neither in both kernels"
            stepper = f"the stepper chose {chose}" if chose else "the stepper ran no team of that size"
            said.append(f"at {n} thread{'s' if n != '1' else ''} {stepper}, {verdict}{mark}")
        lines.append(f"- `{mesh}`: " + "; ".join(said) + ".")
    if not lines:
        return "*No finest level with both layouts in docs/data/lessons/every-lane.json.*\n"
    return "\n".join(lines) + (f"\n\nUndecided: a sign test over the rounds gives p >= {SIGNIFICANCE}. "
                               "Generated by `fem-tools docs lessons` from the table.\n")
