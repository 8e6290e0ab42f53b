"""Long fuzz run of the SVO parsers through the real CLI, one child process per case.

    python fuzz/svo.py --cases N [--seed S]

Rows (per parser): ``.svo`` files (a valid octree with and without far pointers, mutated
by bit flips, byte pokes, 16-bit pointer overwrites and truncation, rendered with the
numba kernel, the numpy kernel or the float64 reference), OBJ, PLY, STL meshes
(mutated valid meshes, hostile tokens, huge indices, NaN/inf and binary garbage, built
with ``svo build``) and binvox grids (the same mutations and hostile headers and runs,
built with ``svo build``). Prints ``harness.HEADER`` and one ``Tally.report()`` row each, then
the first failures on stderr. Exit status 1 if any case failed.
"""

from __future__ import annotations

import argparse
import random
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import harness  # noqa: E402

TOKENS = [b"nan", b"inf", b"-inf", b"1e308", b"-1e308", b"100000000000000000000", b"0", b"-1",
          b"4294967296", b"\xff\xfe", b"f ", b"v ", b"element face 99999999\n", b"property list float float x\n",
          b"\n", b" ", b"/", b"end_header\n", b"solid", b"vertex ", b"dim 65536 65536 65536\n", b"\x01\xff" * 8]


def mutate(data: bytes, rng: random.Random, tokens: bool) -> bytes:
    out = bytearray(data)
    for _ in range(rng.randint(1, 6)):
        op = rng.randrange(5 if tokens else 4)
        if not out:
            break
        pos = rng.randrange(len(out))
        if op == 0:
            out[pos] ^= 1 << rng.randrange(8)
        elif op == 1:
            out[pos] = rng.randrange(256)
        elif op == 2:
            out[pos:pos + 2] = rng.choice([b"\xff\x7f", b"\xff\xff", b"\x00\x00", b"\x01\x00"])
        elif op == 3 and rng.random() < 0.3:
            del out[pos:]
        elif op == 4:
            out[pos:pos] = rng.choice(TOKENS)
    return bytes(out)


def seeds(work: Path) -> dict[str, list[Path]]:
    """Valid inputs to mutate, made with the CLI itself."""
    made = {"svo": [], "obj": [], "ply": [], "stl": [], "binvox": [work / "seed.binvox"]}
    for ext, extra in (("obj", []), ("ply", []), ("ply", ["--ascii"]), ("stl", []), ("stl", ["--ascii"])):
        path = work / f"seed{len(made[ext])}.{ext}"
        check(harness.run_case(["svo", "model", "sphere", "--detail", "6", "-o", str(path), *extra]))
        made[ext].append(path)
    for bits in ("4", "15"):
        path = work / f"seed{bits}.svo"
        check(harness.run_case(["svo", "build", str(made["obj"][0]), "-o", str(path), "--depth", "5",
                                "--ptr-bits", bits, "--binvox", str(made["binvox"][0])]))
        made["svo"].append(path)
    return made


def check(result: harness.CaseResult) -> None:
    if result.returncode != 0:
        sys.exit(f"seed input failed: {' '.join(result.args)}\n{result.stderr}")


def svo_case(rng: random.Random, base: Path, case: Path, out: Path) -> list[str]:
    case.write_bytes(mutate(base.read_bytes(), rng, tokens=False))
    mode = rng.choice([[], ["--kernel", "numpy"], ["--float"]])
    return ["svo", "render", str(case), "-o", str(out), "--size", "32x24", "--stack",
            str(rng.choice([0, 2, 8])), *mode]


def mesh_case(rng: random.Random, base: Path, case: Path, out: Path) -> list[str]:
    if rng.random() < 0.1:
        case.write_bytes(rng.randbytes(rng.randrange(1, 2000)))
    else:
        case.write_bytes(mutate(base.read_bytes(), rng, tokens=True))
    solid = ["--solid"] if rng.random() < 0.3 else []
    return ["svo", "build", str(case), "-o", str(out), "--depth", str(rng.randint(2, 7)), *solid,
            "--max-memory", "1G"]


def binvox_case(rng: random.Random, base: Path, case: Path, out: Path) -> list[str]:
    case.write_bytes(mutate(base.read_bytes(), rng, tokens=True))
    return ["svo", "build", str(case), "-o", str(out), "--max-memory", "1G"]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=200, help="cases per parser")
    ap.add_argument("--seed", type=int, default=13)
    ap.add_argument("--timeout", type=float, default=120.0, help="seconds per case")
    args = ap.parse_args()
    rng = random.Random(args.seed)
    failed = False
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        made = seeds(work)
        print(harness.HEADER)
        for name, key, make in ((".svo", "svo", svo_case), ("OBJ", "obj", mesh_case),
                                ("PLY", "ply", mesh_case), ("STL", "stl", mesh_case),
                                ("binvox", "binvox", binvox_case)):
            tally = harness.Tally(name)
            for i in range(args.cases):
                case, out = work / f"case.{key}", work / ("out.png" if key == "svo" else "out.svo")
                argv = make(rng, rng.choice(made[key]), case, out)
                tally.add(harness.run_case(argv, timeout=args.timeout))
                out.unlink(missing_ok=True)
            print(tally.report(), flush=True)
            tally.print_failures()
            failed |= bool(tally.failures)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
