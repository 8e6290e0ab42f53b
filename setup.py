"""Build the raytracer's C kernels (rend3r/emu/csrc); everything else is in pyproject.toml.

The kernels are one translation unit per working precision and instruction set
(csrc/instances/) plus csrc/kernels.c, compiled in parallel on every core: a unit takes
about a minute at -O3, as each precision's packet kernels are inlined whole.
"""

import os
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

#: IEEE semantics the emulator depends on: no fused multiply-adds, no fast-math; POSIX
#: threads for the teams (csrc/team.c).
UNIX_FLAGS = ["-std=c11", "-O3", "-ffp-contract=off", "-fno-fast-math", "-fno-math-errno", "-Wall", "-Wextra",
              "-Wno-psabi", "-pthread"]
MSVC_FLAGS = ["/O2", "/fp:precise"]
CSRC = Path("rend3r/emu/csrc")


class BuildKernels(build_ext):
    """Adds the float-semantics flags of the compiler in use, and compiles the sources of
    an extension in parallel where the compiler allows it (Unix compilers)."""

    def build_extensions(self) -> None:
        flags = MSVC_FLAGS if self.compiler.compiler_type == "msvc" else UNIX_FLAGS
        for ext in self.extensions:
            ext.extra_compile_args = flags
            ext.extra_link_args = ["-pthread"] if flags is UNIX_FLAGS else []
        if self.compiler.compiler_type == "unix":
            self.compiler.compile = self._compile_parallel
        super().build_extensions()

    def _compile_parallel(self, sources, output_dir=None, macros=None, include_dirs=None, debug=0,
                          extra_preargs=None, extra_postargs=None, depends=None):
        """distutils' CCompiler.compile with the objects built on a thread per core."""
        cc = self.compiler
        macros, objects, extra_postargs, pp_opts, build = cc._setup_compile(
            output_dir, macros, include_dirs, sources, depends, extra_postargs)
        cc_args = cc._get_cc_args(pp_opts, debug, extra_preargs)

        def one(obj: str) -> None:
            src, ext = build[obj]
            cc._compile(obj, src, ext, cc_args, extra_postargs, pp_opts)

        with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
            list(pool.map(one, [obj for obj in objects if obj in build]))
        return objects


setup(
    ext_modules=[
        Extension(
            "rend3r.emu._kernels",
            sources=[*(str(CSRC / name) for name in ("kernels.c", "setup.c", "band.c", "team.c")),
                     *sorted(str(p) for p in (CSRC / "instances").glob("*.c"))],
            depends=[str(p) for p in sorted(CSRC.glob("*.[hi]*"))],
        )
    ],
    cmdclass={"build_ext": BuildKernels},
)
