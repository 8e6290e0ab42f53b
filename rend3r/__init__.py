"""rend3r: the toolchain for the REND3R graphics ISA and rendering device."""

__version__ = "0.1.0"
