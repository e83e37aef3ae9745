#!/usr/bin/env python3
"""Hand-made faults against the test suite: which tests catch each one.

Each fault is a small edit of the source (a wrong sign, a missed factor, a check skipped) of
the kind a change can bring in unnoticed. For each, this puts the fault in, runs the library's
unit tests and the system suite (`cargo test --no-fail-fast --lib`, then `--test suite`),
notes the tests that fail, and puts the source back. A fault no test catches is a hole in the suite.

    python3 tests/mutations.py              # every fault; a Markdown table on stdout
    python3 tests/mutations.py NAME [NAME]  # only these

Run it on a clean tree (it restores each file with `git checkout`); it takes about eight
minutes a fault on two cores. A fault can make a test run forever: each test binary gets a
time limit, and the tests still running when it is reached count as caught ("hung"). Each edit must match its file exactly once, so a fault whose
code has moved or changed is an error, not a silent pass: update the edit with the code.
Exit status 1 if a fault survives.
"""

import os
import re
import signal
import subprocess
import sys
import time

# (name, what it breaks, [(file, text, replacement)])
FAULTS = [
    (
        "impulse-sign",
        "the first circle of a hit is pushed the wrong way",
        [("src/collision/contact.rs", "*va -= n * (impulse * wa);", "*va += n * (impulse * wa);")],
    ),
    (
        "restitution-ignored",
        "every hit of the shared impulse is elastic",
        [(
            "src/collision/contact.rs",
            "let impulse = -(1.0 + restitution) * approach / w;",
            "let impulse = -2.0 * approach / w + 0.0 * restitution;",
        )],
    ),
    (
        "restitution-max",
        "two surfaces meet with the bouncier one's restitution",
        [("src/collision/contact.rs", "    a.min(b)\n", "    a.max(b)\n")],
    ),
    (
        "toi-one-ulp-late",
        "a pair's time of impact (scalar path) one ulp late",
        [(
            "src/collision/toi.rs",
            "let t = c / (-b + disc.sqrt());\n    t.is_finite().then_some(t.max(0.0))",
            "let t = c / (-b + disc.sqrt());\n    t.is_finite().then_some(t.max(0.0).next_up())",
        )],
    ),
    (
        "stale-events-kept",
        "exact processes a pair event whose partner has collided since",
        [(
            "src/solvers/exact/engine/mod.rs",
            "&& self.counter[event.partner as usize] != event.partner_count",
            "&& self.counter[event.partner as usize] != event.partner_count && false",
        )],
    ),
    (
        "wake-never-fires",
        "a sleeping island touched by a moving circle stays asleep",
        [(
            "src/step/sleep/islands.rs",
            "(true, false) => hit[k as usize] = true,\n            (false, true) => hit[l as usize] = true,",
            "(true, false) => {}\n            (false, true) => {}",
        )],
    ),
    (
        "soft-no-bounce",
        "soft's restitution pass is skipped",
        [(
            "src/solvers/soft/solve.rs",
            "    restitution(bodies, (walls, pairs), bouncing, &mut work);\n",
            "    let _ = (restitution, bouncing);\n",
        )],
    ),
    (
        "soft-cold-start",
        "soft's pairs start each step from no impulse (no warm start)",
        [("src/solvers/soft/solve.rs", "    cache.warm_start(&bodies.id, pairs, rows);\n", "")],
    ),
    (
        "friction-doubled",
        "soft's Coulomb bound is twice mu times the push",
        [(
            "src/solvers/soft/contacts.rs",
            "let most = |k: f64| (k * impulse).max(0.0);",
            "let most = |k: f64| (2.0 * k * impulse).max(0.0);",
        )],
    ),
    (
        "stencil-misses-up-left",
        "the periodic pair scan skips the cell above and to the left",
        [(
            "src/collision/broad_phase/cells.rs",
            "for cx in [left, x, right] {",
            "for cx in [x, right, left][..2].iter().copied() {",
        )],
    ),
    (
        "wall-restitution-twice",
        "a wall hit takes its restitution once too often",
        [(
            "src/step/boundary/mod.rs",
            "restitution.powi(n.min(i32::MAX as u64) as i32)",
            "restitution.powi(n.min(i32::MAX as u64) as i32 + 1)",
        )],
    ),
    (
        "half-gravity",
        "the time-stepped solvers' gravity kick is halved",
        [("src/step/forces.rs", "let dv = g * dt.0;", "let dv = g * dt.0 * 0.5;")],
    ),
    (
        "checksum-unchecked",
        "a checkpoint's checksum is not compared",
        [(
            "src/tools/checkpoint/bytes.rs",
            "if crc32fast::hash(fields).to_le_bytes() != checksum",
            "if false && crc32fast::hash(fields).to_le_bytes() != checksum",
        )],
    ),
]


def apply(edits):
    for path, text, replacement in edits:
        with open(path, encoding="utf-8") as f:
            source = f.read()
        found = source.count(text)
        if found != 1:
            raise SystemExit(f"{path}: the fault's text is there {found} times, not once: {text!r}")
        with open(path, "w", encoding="utf-8") as f:
            f.write(source.replace(text, replacement))


def restore(edits):
    subprocess.run(["git", "checkout", "--"] + sorted({p for p, _, _ in edits}), check=True)


def failing_tests(output):
    return sorted(set(re.findall(r"^test (\S+) \.\.\. FAILED$", output, re.MULTILINE)))


# Each test binary's time limit, in seconds: several times what it takes on two busy cores.
LIMITS = {"--lib": 600, "--test": 1500}


def run_limited(command, limit):
    """`command`'s output, and the tests it left running if it was stopped at `limit` seconds
    (with every process it started)."""
    process = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True
    )
    try:
        output, _ = process.communicate(timeout=limit)
        return output, []
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        output, _ = process.communicate()
        started = set(re.findall(r"^test (\S+) has been running for over", output, re.MULTILINE))
        ended = set(re.findall(r"^test (\S+) \.\.\. ", output, re.MULTILINE))
        return output, sorted(started - ended) or ["(a test binary that never ended)"]


def caught_by(name):
    """The tests that fail, or hang, with fault `name` in place."""
    build = subprocess.run(
        ["cargo", "test", "--no-run", "--lib", "--test", "suite"], capture_output=True, text=True
    )
    if build.returncode != 0:
        raise SystemExit(f"{name}: the fault does not compile:\n{build.stderr[-3000:]}")
    failed, hung = [], []
    for target in (["--lib"], ["--test", "suite"]):
        output, stuck = run_limited(["cargo", "test", "--no-fail-fast", *target], LIMITS[target[0]])
        failed += failing_tests(output)
        hung += stuck
    return failed, hung


def main():
    chosen = sys.argv[1:]
    unknown = set(chosen) - {name for name, _, _ in FAULTS}
    if unknown:
        raise SystemExit(f"no such fault: {', '.join(sorted(unknown))}")
    if subprocess.run(["git", "diff", "--quiet"]).returncode != 0:
        raise SystemExit("the tree has changes: commit or stash them first")
    survivors = []
    print("| fault | what it breaks | tests that fail | for example |")
    print("|---|---|---:|---|")
    for name, what, edits in FAULTS:
        if chosen and name not in chosen:
            continue
        apply(edits)
        start = time.monotonic()
        try:
            failed, hung = caught_by(name)
        finally:
            restore(edits)
        caught = failed + [f"{test} (hung)" for test in hung]
        if not caught:
            survivors.append(name)
        example = ", ".join(f"`{t}`" for t in caught[:3]) or "**none: it survives**"
        print(f"| `{name}` | {what} | {len(caught)} | {example} |", flush=True)
        print(f"{name}: {len(caught)} caught in {time.monotonic() - start:.0f} s", file=sys.stderr)
    if survivors:
        print(f"survivors: {', '.join(survivors)}", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
