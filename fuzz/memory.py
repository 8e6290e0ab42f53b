"""Long fuzz run of the memory-image readers through the CLI, one row per format.

Seeds are the real images ``rend3r asm`` writes for every source in ``asm/`` and
``programs/`` in every format it writes; each case mutates one (bit flips, truncation,
hostile snippets, deletion, duplication, CRLF) and runs ``rend3r disasm FILE`` in a child
(``fuzz/harness.py``: own time, peak RSS, 4 GiB address space); every tenth case also runs
``rend3r emulate FILE --frames 1 -o x.png``. Each format's row also counts its extremes:
files at and over the size and word limits.

    python fuzz/memory.py --cases 150 [--seed 1]

Exit status 1 if any case failed.
"""

from __future__ import annotations

import argparse
import random
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import harness  # noqa: E402

from rend3r.asm.formats import FORMATS, byte_limit  # noqa: E402
from rend3r.asm.formats.common import MAX_WORDS  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
SNIPPETS = [
    b"\x00", b"\r\n", b"\r", b"\n", b"\xff", b"\xef\xbb\xbf", b"@ffffff", b"@fffff", b"@" + b"f" * 60,
    b"9" * 5000, b"f" * 5000, b"100000000", b"memory_initialization_radix=10;",
    b"memory_initialization_radix=2;", b"memory_initialization_vector=", b";", b",", b":02000004FFFFFC\n",
    b":020000040010EA\n", b":00000001FF\n", b"/*", b"//", b"|", b" | ffff | ", b"\n" * 5000, b" " * 5000,
]


def seeds(workdir: Path) -> dict[str, list[bytes]]:
    """Every format's images of every source that assembles."""
    out: dict[str, list[bytes]] = {fmt: [] for fmt in FORMATS}
    flags = [arg for fmt in FORMATS for arg in ("-f", fmt)]
    for src in sorted([*ROOT.glob("asm/*.asm"), *ROOT.glob("programs/*.asm")]):
        stem = workdir / src.stem
        done = subprocess.run([sys.executable, "-m", "rend3r", "asm", str(src), "-o", str(stem), *flags],
                              capture_output=True)
        if done.returncode == 0:
            for fmt, spec in FORMATS.items():
                out[fmt].append(Path(f"{stem}{spec.extension}").read_bytes())
    return out


def mutate(rng: random.Random, data: bytes) -> bytes:
    buf = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        at = rng.randint(0, len(buf))
        kind = rng.choice(["flip", "truncate", "insert", "random", "delete", "duplicate", "crlf"])
        if kind == "flip" and at < len(buf):
            buf[at] ^= 1 << rng.randrange(8)
        elif kind == "truncate":
            del buf[at:]
        elif kind == "insert":
            buf[at:at] = rng.choice(SNIPPETS)
        elif kind == "random":
            buf[at:at] = rng.randbytes(rng.randint(1, 16))
        elif kind == "delete":
            del buf[at:at + rng.randint(1, 64)]
        elif kind == "duplicate":
            buf[at:at] = buf[at:at + rng.randint(1, 4096)]
        else:
            buf = bytearray(buf.replace(b"\n", b"\r\n"))
    return bytes(buf)


def extremes(fmt: str) -> list[bytes]:
    """Files at the limits: the largest zero-filled image, one word over it, a file one
    byte over the size limit, and a file at the size limit made of what costs most."""
    over = b"0" * (byte_limit(fmt) + 1)
    if fmt == "bin":
        return [bytes(4 * MAX_WORDS), bytes(4 * MAX_WORDS + 4), over]
    if fmt == "ihex":
        top = (MAX_WORDS * 4 - 4)
        ext = _ihex(bytes([2, 0, 0, 4]) + (top >> 16).to_bytes(2, "big"))
        last = _ihex(bytes([4]) + (top & 0xFFFF).to_bytes(2, "big") + bytes([0, 0, 0, 2, 0]))
        ones = b"".join(_ihex(bytes([1, (a >> 8) & 0xFF, a & 0xFF, 0, 7])) for a in range(0, 1 << 16, 2))
        return [ext + last + b":00000001FF\n", ones * (byte_limit(fmt) // len(ones)), over,
                b"\n" * byte_limit(fmt)]
    if fmt == "coe":
        head = b"memory_initialization_radix=2;\nmemory_initialization_vector=\n"
        return [head + b"1" * 32 + b";", head + b"0,\n" * MAX_WORDS + b"0;", over,
                b";" * byte_limit(fmt), head + b"1" * (byte_limit(fmt) - len(head) - 1) + b";"]
    if fmt == "lst":
        return [b"".join(f" | {a:x} | 0 |\n".encode() for a in range(MAX_WORDS)), over,
                b"\n" * byte_limit(fmt), b" | 0 | " + b"0 " * (byte_limit(fmt) // 2 - 8) + b"\n"]
    return [f"@{MAX_WORDS - 1:x} 1\n".encode(), b"0\n" * (MAX_WORDS + 1), over,
            b"/**/" * (byte_limit(fmt) // 4), b"\n" * byte_limit(fmt), b"@" + b"f" * (byte_limit(fmt) - 2)]


def _ihex(body: bytes) -> bytes:
    return f":{body.hex().upper()}{(-sum(body)) & 0xFF:02X}\n".encode()


def run_format(fmt: str, images: list[bytes], cases: int, rng: random.Random, workdir: Path) -> harness.Tally:
    tally = harness.Tally(fmt)
    path = workdir / f"case{FORMATS[fmt].extension}"
    inputs = [mutate(rng, rng.choice(images)) for _ in range(cases)] + extremes(fmt)
    for n, data in enumerate(inputs):
        path.write_bytes(data)
        tally.add(harness.run_case(["disasm", str(path), "-o", str(workdir / "out.asm")], timeout=60))
        if n % 10 == 0:
            tally.add(harness.run_case(["emulate", str(path), "--frames", "1", "-o", str(workdir / "x.png")],
                                       timeout=120))
    return tally


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=150, help="mutated cases per format (extremes come on top)")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    rng = random.Random(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        images = seeds(workdir)
        print(harness.HEADER)
        failed = False
        for fmt in FORMATS:
            tally = run_format(fmt, images[fmt], args.cases, rng, workdir)
            print(tally.report(), flush=True)
            tally.print_failures()
            failed |= bool(tally.failures)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
