"""Long fuzz run of ``rend3r emulate``'s options and outputs and of ``trace-diff``'s JSON.

Each case is a child process (fuzz/harness.py: its own time, peak RSS, crash and traceback
counts). Three rows:

- trace JSON: a real trace from ``emulate --trace-pixel``, mutated (characters, a field
  given a wrong type, nesting up to 200,000 deep, numbers of up to 100,000 digits, spliced
  lines), compared both ways with ``trace-diff``;
- emulate options: one of ``--size``, ``-o``/``--depth-image``/``--provenance`` patterns,
  ``--trace-pixel``, ``--background``, ``--gif`` given a hostile value, the others valid; a
  failed run must leave no file behind (counted under "outputs left");
- emulate values: real programs with float16 operands replaced by inf, NaN, 65504 and
  subnormals, in every mode and precision; no numpy warning may reach stderr.

Exit status 1 if any case failed, left an output or printed a numpy warning.

Usage: ``python fuzz/emulate.py --cases N [--seed S]``.
"""

from __future__ import annotations

import argparse
import json
import random
import shutil
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import harness  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
PROGRAMS = ["sphere", "shadow", "lights", "camera", "tri_cube", "tri_sphere", "hybrid_mix", "cylinder_cone"]
HOSTILE_NUMBERS = ["0", "-1", "8193", "99999999999999999999", "1" * 5000, "0x10", "1e3", "１２", "", " ", "nan"]
PATTERN_PARTS = ["f", "_", "{n}", "{n:03}", "{n:032}", "{n:033}", "{n[0]}", "{n:999999999}", "{}", "{0}", "{{",
                 "}}", "{n!r}", "{n:>9}", "{n.real}", "{", "}", "sub/", "../", "..", "f" * 200, "é", " ", "%s", "*"]
SPECIALS = [0x7C00, 0xFC00, 0x7E00, 0xFE00, 0x7BFF, 0xFBFF, 0x0001, 0x8001, 0x03FF, 0x0400, 0x0000, 0x8000]


def _pattern(rng: random.Random) -> str:
    return "".join(rng.choice(PATTERN_PARTS) for _ in range(rng.randint(1, 5)))


def _number(rng: random.Random) -> str:
    return rng.choice(HOSTILE_NUMBERS + [str(rng.randint(0, 64))] * 4)


def _hostile(rng: random.Random, out: Path) -> tuple[str, str]:
    """One option and a hostile value for it."""
    option = rng.choice(["--size", "-o", "--depth-image", "--provenance", "--trace-pixel", "--background", "--gif",
                         "--max-memory"])
    if option == "--size":
        sizes = ["8192x8192", "8192x1", "1x8192", "4096x4096", "0x0", "-5x5", "1x1"]
        value = rng.choice(sizes + [f"{_number(rng)}{rng.choice(['x', 'X', ' x ', ','])}{_number(rng)}"] * 6)
    elif option in ("-o", "--depth-image", "--provenance"):
        value = f"{out}/{_pattern(rng)}{rng.choice(['.png', '.npy', '.PNG', '', '.gif'])}"
    elif option == "--trace-pixel":
        value = f"{_number(rng)}{rng.choice([',', ';', ', ', ',,'])}{_number(rng)}"
    elif option == "--background":
        value = rng.choice([hex(rng.randint(-5, 0x1FFFF)), _number(rng), "0x" + "f" * rng.randint(0, 9), "0b1_0"])
    elif option == "--gif":
        value = rng.choice([f"{out}/a.gif", f"{out}/taken.gif", f"{out}/nope/a.gif", f"{out}/{'g' * 300}.gif",
                            f"{out}/f.png"])
    else:
        value = rng.choice(["1M", "100M", "2G", "0", "1x", "99999999999T", "1.5G", ""])
    return option, value


def run_options(cases: int, rng: random.Random, work: Path) -> tuple[harness.Tally, int]:
    tally, left = harness.Tally("emulate options (size, name patterns, trace pixel, background, gif)"), 0
    for _ in range(cases):
        out = work / "out"
        shutil.rmtree(out, ignore_errors=True)
        out.mkdir()
        (out / "taken.gif").mkdir()
        option, value = _hostile(rng, out)
        given = {"-o": f"{out}/f_{{n}}.png", "--size": "16x12", "--trace-pixel": "3,3", "--background": "0x001F",
                 option: value}
        program = ROOT / "programs" / rng.choice(["sphere.asm", "animation.asm", "tri_cube.asm"])
        args = ["emulate", str(program), *[x for kv in given.items() for x in kv], "--frames", "2",
                "--trace", f"{out}/t.jsonl"]
        result = harness.run_case(args, timeout=180)
        tally.add(result)
        if result.returncode != 0:
            stray = [p for p in out.rglob("*") if p.name != "taken.gif"]
            if stray:
                left += 1
                print(f"outputs left after exit {result.returncode}: {args} -> {stray[:3]}", file=sys.stderr)
    return tally, left


def _real_trace(work: Path) -> str:
    trace = work / "real.jsonl"
    args = ["emulate", str(ROOT / "programs" / "shadow.asm"), "-o", str(work / "r.png"), "--size", "32x24",
            "--trace-pixel", "16,12", "--trace-pixel", "0,0", "--trace", str(trace)]
    result = harness.run_case(args)
    if result.returncode != 0:
        raise SystemExit(f"cannot make a real trace: {result.stderr}")
    return trace.read_text()


def _mutate(text: str, rng: random.Random) -> bytes:
    lines = text.splitlines()
    for _ in range(rng.randint(1, 3)):
        i = rng.randrange(len(lines))
        kind = rng.choice(["bytes", "field", "nest", "number", "splice"])
        if kind == "bytes":
            at = rng.randint(0, len(lines[i]))
            junk = "".join(chr(rng.choice([0, 10, 34, 44, 58, 91, 93, 123, 125, 0xE9, 0x2028, rng.randint(32, 126)]))
                           for _ in range(rng.randint(1, 6)))
            lines[i] = lines[i][:at] + junk + lines[i][at + rng.randint(0, 4):]
        elif kind == "field":
            try:
                record = json.loads(lines[i])
            except ValueError:
                continue
            key = rng.choice(["frame", "pixel", "shape", "stage", "hex", "dec"])
            record[key] = rng.choice([None, True, -1, 2**70, 1e308, "nan", "0x" + "f" * 40, [1], [1, 2, 3],
                                      {"x": 1}, "", "s" * 500, [-1, 0], [0.5, 1], "0x10000000000000000"])
            lines[i] = json.dumps(record)
        elif kind == "nest":
            depth = rng.choice([17, 1000, 100_000, 200_000])
            lines[i] = "[" * depth + "]" * rng.choice([0, depth])
        elif kind == "number":
            digits = rng.choice([25, 4300, 4301, 100_000])
            key = rng.choice(["dec", "frame", "shape"])
            lines[i] = lines[i].replace(f'"{key}": ', f'"{key}": {"9" * digits}, "was": ', 1)
        else:
            lines.insert(i, lines[rng.randrange(len(lines))][: rng.randint(0, 60)])
    data = ("\n".join(lines) + "\n").encode("utf-8", "surrogatepass")
    if rng.random() < 0.05:
        data += bytes([0xFF, 0xFE])
    return data


def run_traces(cases: int, rng: random.Random, work: Path) -> harness.Tally:
    tally = harness.Tally("trace JSON (trace-diff)")
    real = _real_trace(work)
    a, b = work / "a.jsonl", work / "b.jsonl"
    a.write_text(real)
    for _ in range(cases):
        b.write_bytes(_mutate(real, rng))
        first, second = (a, b) if rng.random() < 0.5 else (b, a)
        tally.add(harness.run_case(["trace-diff", str(first), str(second)], timeout=60, verdicts=(1,)))
    return tally


def run_values(cases: int, rng: random.Random, work: Path) -> tuple[harness.Tally, int]:
    tally, warned = harness.Tally("emulate values (inf, NaN, 65504, subnormal operands)"), 0
    images = {}
    for name in PROGRAMS:
        mem = work / f"{name}.mem"
        harness.run_case(["asm", str(ROOT / "programs" / f"{name}.asm"), "-o", str(mem)])
        images[name] = [int(w, 16) for w in mem.read_text().split() if not w.startswith("@")]
    for _ in range(cases):
        words = list(images[rng.choice(PROGRAMS)])
        for _ in range(rng.randint(1, 8)):
            i = rng.randrange(1, len(words))
            half = rng.choice([16, 0]) if rng.random() < 0.3 else 16
            words[i] = (words[i] & ~(0xFFFF << half)) | (rng.choice(SPECIALS) << half)
        mem = work / "m.mem"
        mem.write_text("".join(f"{w:08x}\n" for w in words))
        mode = rng.choice(["raytrace", "raster", "hybrid"])
        trace = ["--trace-pixel", "5,5"] if mode != "hybrid" else []
        args = ["emulate", str(mem), "-o", str(work / "v.png"), "--depth-image", str(work / "d.png"),
                "--provenance", str(work / "p.png"), "--size", "24x18", "--mode", mode, "--frames", "1",
                "--precision", rng.choice(["fp16", "fp32", "fp64"]), *trace,
                *(["--profile", "rend3r-2022"] if rng.random() < 0.3 else [])]
        result = harness.run_case(args, timeout=120)
        tally.add(result)
        if "Warning" in result.stderr or "encountered" in result.stderr:
            warned += 1
            print(f"warning on stderr: {args}\n{result.stderr[-500:]}", file=sys.stderr)
    return tally, warned


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=100, help="cases per row")
    parser.add_argument("--seed", type=int, default=13)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        traces = run_traces(args.cases, rng, work)
        options, left = run_options(args.cases, rng, work)
        values, warned = run_values(args.cases, rng, work)
    print(harness.HEADER)
    for tally in (traces, options, values):
        print(tally.report())
    print(f"\noutputs left after a failed emulate: {left}; numpy warnings on stderr: {warned}")
    for tally in (traces, options, values):
        tally.print_failures()
    sys.exit(1 if left or warned or any(t.failures for t in (traces, options, values)) else 0)


if __name__ == "__main__":
    main()
