"""Build the raytracer's C kernels (rend3r/emu/csrc); everything else is in pyproject.toml."""

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

#: IEEE semantics the emulator depends on: no fused multiply-adds, no fast-math.
UNIX_FLAGS = ["-std=c11", "-O3", "-ffp-contract=off", "-fno-fast-math", "-fno-math-errno", "-Wall", "-Wextra",
              "-Wno-psabi"]
MSVC_FLAGS = ["/O2", "/fp:precise"]


class BuildKernels(build_ext):
    """Adds the float-semantics flags of the compiler in use."""

    def build_extensions(self) -> None:
        flags = MSVC_FLAGS if self.compiler.compiler_type == "msvc" else UNIX_FLAGS
        for ext in self.extensions:
            ext.extra_compile_args = flags
        super().build_extensions()


setup(
    ext_modules=[
        Extension(
            "rend3r.emu._kernels",
            sources=["rend3r/emu/csrc/kernels.c", "rend3r/emu/csrc/kernels_avx2.c"],
            depends=[f"rend3r/emu/csrc/{name}" for name in (
                "bounds.h", "colour.h", "cull.h", "datapath.inc", "fround.h", "grids.h", "instances.inc", "kernels.h",
                "simd.h")],
        )
    ],
    cmdclass={"build_ext": BuildKernels},
)
