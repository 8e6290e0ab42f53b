"""Long fuzz run of the assembler through the CLI: ``rend3r asm FILE -o OUT`` in a child
per case (``fuzz/harness.py``: own time, peak RSS, 4 GiB address space).

Four families of cases, one table row each, and a row for all of them:

* mutated: a real source from ``asm/`` or ``programs/`` with insertions, deletions,
  replacements, duplicated lines and pieces repeated hundreds of times;
* bytes: random bytes, and random bytes spliced into a real source;
* nesting: expressions, ``.rept`` blocks and ``.include`` chains at, around and far past
  each depth limit;
* limits: the reproductions of issue 13 and the worst case of each limit (a 1 MB line,
  a line at the 4,096-character limit, bodies that run to the statement cap, 10^4000
  squared, ``/dev/zero``), every one of them in every run.

    python fuzz/asm.py --cases 2000 [--seed 1]
"""

from __future__ import annotations

import argparse
import random
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import harness  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
INCLUDE = ROOT / "asm" / "include"
PIECES = ["-", "+", "*", "/", "(", ")", ",", "0", "1e4000", "1e-4000", "0x", "0h", "0b", "_", ".", "e", ";", "//",
          '"', "=", "A", "i", ".rept 3, i\n", ".rept 1048575\n", ".endr\n", '.include "consts.inc"\n',
          '.include "cycle_a.inc"\n', '.include "' + "n" * 300 + '"\n', ".isa_ext hybrid\n", "ts triangle\n",
          ".word ", "sp ", "lt 63, ", "cam xloc, ", "\t", " " * 64, "\x00", "\u00e9", "\ufeff", "\r", "\n",
          "A0 = 1e3999\nA1 = A0 * A0\n", ".rept 1000000, i\nlt i, xloc, 1\n.endr\n"]


def mutate(rng: random.Random, text: str) -> str:
    for _ in range(rng.randint(1, 6)):
        at = rng.randint(0, len(text))
        kind = rng.choice(["insert", "delete", "replace", "dup-line", "repeat"])
        if kind == "insert":
            text = text[:at] + rng.choice(PIECES) + text[at:]
        elif kind == "delete":
            text = text[:at] + text[at + rng.randint(1, 40):]
        elif kind == "replace":
            text = text[:at] + rng.choice(PIECES) + text[at + 1:]
        elif kind == "repeat":
            text = text[:at] + rng.choice(PIECES) * rng.randint(2, 5000) + text[at:]
        else:
            lines = text.split("\n")
            i = rng.randrange(len(lines))
            lines[i:i] = [lines[i]] * rng.randint(1, 2000)
            text = "\n".join(lines)
    return text


def random_bytes(rng: random.Random, seeds: list[bytes]) -> bytes:
    noise = rng.randbytes(rng.randint(0, 20_000))
    if rng.random() < 0.5:
        return noise
    seed = rng.choice(seeds)
    at = rng.randint(0, len(seed))
    return seed[:at] + noise + seed[at:]


def nesting(rng: random.Random, work: Path) -> str:
    n = rng.choice([31, 32, 33, 63, 64, 65, 199, 200, 201, 1000, 10_000])
    kind = rng.choice(["neg", "sum", "parens", "mixed", "rept", "include"])
    if kind == "rept":
        return ".rept 1\n" * n + "nr\n" + ".endr\n" * n + "er\ner\n"
    if kind == "include":
        n = min(n, 300)
        for i in range(n):
            (work / f"chain{i}.inc").write_text(f'.include "chain{i + 1}.inc"\n' if i < n - 1 else "nr\n")
        return '.include "chain0.inc"\ner\ner\n'
    operand = {"neg": "-" * n + "1", "sum": "+".join(["1"] * n), "parens": "(" * n + "1" + ")" * n,
               "mixed": "(-" * n + "1" + ")" * n}[kind]
    head = rng.choice(["cam xloc, ", "A = ", ".word ", ".rept ", "lt 0, xloc, "])
    return head + operand + "\n.endr\ner\ner\n"


def limits() -> list[tuple[str, str]]:
    """(name, source) of each worst case (``/dev/zero`` is run besides)."""
    squarings = "A0 = 1e3999\n" + "".join(f"A{i + 1} = A{i} * A{i}\n" for i in range(12))
    return [
        ("neg990", "cam xloc, " + "-" * 990 + "1\ner\ner\n"),
        ("sum1000", "cam xloc, " + "+".join(["0"] * 1000) + "\ner\ner\n"),
        ("rept500", ".rept 1\n" * 500 + "nr\n" + ".endr\n" * 500),
        ("product", ".word 1e4000*1e4000\ner\ner\n"),
        ("squarings", squarings + "cam xloc, A12\ner\ner\n"),
        ("longname", '.include "' + "a" * 300 + '.asm"\n'),
        ("spaces20k", "cam xloc, 1" + " " * 20_000 + "(\n"),
        ("line1MB", "cam xloc, 1" + " " * (1 << 20) + "(\n"),
        ("line4096commas", "cam xloc, " + "1," * 2043 + "\n"),
        ("line4096parens", "cam xloc, " + "(" * 4085 + "\n"),
        ("errors1M", ".rept 1048000, i\nlt i + 64, xloc, 1\n.endr\n"),
        ("cap_nr", ".rept 1048575\nnr\n.endr\ner\ner\n"),
        ("cap_sp", ".rept 1048575, i\nsp i, xloc, yloc, i * 0.001, 1\n.endr\ner\ner\n"),
        ("cap_expr", ".rept 1048575, i\nA = " + "+".join(["i"] * 100) + "\n.endr\ner\ner\n"),
        ("cap_parsed", (".word " + "1," * 2044 + "1\n") * 520),
        ("cap_include", '.rept 1048575\n.include "consts.inc"\n.endr\ner\ner\n'),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=2000, help="random cases (the limit cases run besides)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds before a case counts as a hang")
    args = parser.parse_args()
    rng = random.Random(args.seed)
    sources = sorted([*ROOT.glob("asm/*.asm"), *INCLUDE.glob("*.inc"), *ROOT.glob("programs/*.asm")])
    seeds = [p.read_bytes() for p in sources]
    texts = [s.decode("utf-8", "replace") for s in seeds]
    tallies = {name: harness.Tally(f"asm: {name}") for name in ("mutated", "bytes", "nesting", "limits")}
    total = harness.Tally("asm: all")
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        src, out = work / "case.asm", work / "case.mem"

        def run(family: str, data: bytes | None, path: Path = src) -> harness.CaseResult:
            if data is not None:
                path.write_bytes(data)
            result = harness.run_case(["asm", str(path), "-I", str(INCLUDE), "-o", str(out)],
                                      timeout=args.timeout)
            if result.returncode in (0, 1) and (result.returncode == 0) != out.exists():
                # an output without success, or success without an output: count it as unclear
                result = harness.CaseResult(result.args, 2, result.seconds, result.rss_bytes,
                                            f"output {'kept' if out.exists() else 'missing'}", False)
            out.unlink(missing_ok=True)
            tallies[family].add(result)
            total.add(result)
            return result

        for name, text in [*limits(), ("/dev/zero", None)]:
            r = run("limits", None if text is None else text.encode(), Path(name) if text is None else src)
            last = r.stderr.strip().splitlines()[-1][:100] if r.stderr.strip() else ""
            print(f"  {name}: exit {r.returncode}, {r.seconds:.2f} s, {r.rss_bytes / 2**20:.0f} MiB: {last}",
                  file=sys.stderr)
        for i in range(args.cases):
            family = rng.choice(["mutated", "mutated", "bytes", "nesting"])
            if family == "mutated":
                data = mutate(rng, rng.choice(texts)).encode("utf-8", "surrogatepass")
            elif family == "bytes":
                data = random_bytes(rng, seeds)
            else:
                data = nesting(rng, work).encode()
            run(family, data)
            if (i + 1) % 100 == 0:
                print(f"  {i + 1} cases", file=sys.stderr)
    print(harness.HEADER)
    for tally in [*tallies.values(), total]:
        print(tally.report())
    for tally in tallies.values():
        tally.print_failures()
    print(f"worst time: {' '.join(total.worst_args)[:120]}", file=sys.stderr)
    sys.exit(1 if total.failures else 0)


if __name__ == "__main__":
    main()
