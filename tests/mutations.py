#!/usr/bin/env python3
"""Hand-made faults against the test suite: which tests catch each one.

Each fault is a small edit of the source (a wrong sign, a missed factor, a check skipped) of
the kind a change can bring in unnoticed. For each, this puts the fault in, runs the library's
unit tests and the system suite (`cargo test --lib --test suite --no-fail-fast`), notes the
tests that fail, and puts the source back. A fault no test catches is a hole in the suite.

    python3 tests/mutations.py              # every fault; a Markdown table on stdout
    python3 tests/mutations.py NAME [NAME]  # only these

Run it on a clean tree (it restores each file with `git checkout`); it takes about eight
minutes a fault on two cores. Each edit must match its file exactly once, so a fault whose
code has moved or changed is an error, not a silent pass: update the edit with the code.
Exit status 1 if a fault survives.
"""

import re
import subprocess
import sys
import time

# (name, what it breaks, [(file, text, replacement)])
FAULTS = [
    (
        "impulse-sign",
        "the first circle of a hit is pushed the wrong way",
        [("src/collide/contact.rs", "*va -= n * (impulse * wa);", "*va += n * (impulse * wa);")],
    ),
    (
        "restitution-ignored",
        "every hit of the shared impulse is elastic",
        [(
            "src/collide/contact.rs",
            "let impulse = -(1.0 + restitution) * approach / w;",
            "let impulse = -2.0 * approach / w + 0.0 * restitution;",
        )],
    ),
    (
        "restitution-max",
        "two surfaces meet with the bouncier one's restitution",
        [("src/collide/contact.rs", "    a.min(b)\n", "    a.max(b)\n")],
    ),
    (
        "toi-one-ulp-late",
        "a pair's time of impact (scalar path) one ulp late",
        [(
            "src/exact/toi.rs",
            "let t = c / (-b + disc.sqrt());\n    t.is_finite().then_some(t.max(0.0))",
            "let t = c / (-b + disc.sqrt());\n    t.is_finite().then_some(t.max(0.0).next_up())",
        )],
    ),
    (
        "stale-events-kept",
        "exact processes a pair event whose partner has collided since",
        [(
            "src/exact/engine/mod.rs",
            "&& self.counter[event.partner as usize] != event.partner_count",
            "&& self.counter[event.partner as usize] != event.partner_count && false",
        )],
    ),
    (
        "wake-never-fires",
        "a sleeping island touched by a moving circle stays asleep",
        [(
            "src/sleep/islands.rs",
            "(true, false) => hit[k as usize] = true,\n            (false, true) => hit[l as usize] = true,",
            "(true, false) => {}\n            (false, true) => {}",
        )],
    ),
    (
        "soft-no-bounce",
        "soft's restitution pass is skipped",
        [(
            "src/soft/solve.rs",
            "    restitution(bodies, (walls, pairs), bouncing, &mut work);\n",
            "    let _ = (restitution, bouncing);\n",
        )],
    ),
    (
        "soft-cold-start",
        "soft's pairs start each step from no impulse (no warm start)",
        [("src/soft/solve.rs", "    cache.warm_start(&bodies.id, pairs, rows);\n", "")],
    ),
    (
        "friction-doubled",
        "soft's Coulomb bound is twice mu times the push",
        [(
            "src/soft/contacts.rs",
            "let most = |k: f64| (k * impulse).max(0.0);",
            "let most = |k: f64| (2.0 * k * impulse).max(0.0);",
        )],
    ),
    (
        "stencil-misses-up-left",
        "the periodic pair scan skips the cell above and to the left",
        [(
            "src/collide/broad_phase/cells.rs",
            "for cx in [left, x, right] {",
            "for cx in [x, right, left][..2].iter().copied() {",
        )],
    ),
    (
        "wall-restitution-twice",
        "a wall hit takes its restitution once too often",
        [(
            "src/boundary/mod.rs",
            "restitution.powi(n.min(i32::MAX as u64) as i32)",
            "restitution.powi(n.min(i32::MAX as u64) as i32 + 1)",
        )],
    ),
    (
        "half-gravity",
        "the time-stepped solvers' gravity kick is halved",
        [("src/forces.rs", "let dv = g * dt.0;", "let dv = g * dt.0 * 0.5;")],
    ),
    (
        "checksum-unchecked",
        "a checkpoint's checksum is not compared",
        [(
            "src/checkpoint/bytes.rs",
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
            run = subprocess.run(
                ["cargo", "test", "--lib", "--test", "suite", "--no-fail-fast"],
                capture_output=True,
                text=True,
            )
        finally:
            restore(edits)
        output = run.stdout + run.stderr
        if "error[E" in output or "could not compile" in output:
            raise SystemExit(f"{name}: the fault does not compile:\n{output[-3000:]}")
        failed = failing_tests(output)
        if not failed:
            survivors.append(name)
        example = ", ".join(f"`{t}`" for t in failed[:3]) or "**none: it survives**"
        print(f"| `{name}` | {what} | {len(failed)} | {example} |", flush=True)
        print(f"{name}: {len(failed)} failed in {time.monotonic() - start:.0f} s", file=sys.stderr)
    if survivors:
        print(f"survivors: {', '.join(survivors)}", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
