"""The REND3R ISA as data: opcodes, bit fields and property tables.

This module is the single source of truth for the encoding. The encoder, decoder,
assembler, disassembler, emulator and ``docs/isa.md`` all read it; nothing re-types it.
Sources: the paper's Figures 2-4 and the original device's public SystemVerilog source.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum, IntEnum


class Opcode(IntEnum):
    """Bits 2:0 of every word except SD (which has none)."""

    F = 0b000
    C = 0b001
    L = 0b011
    SE = 0b101


#: Opcodes the original RTL decodes as "unsupported, do nothing" (100 was reserved there
#: for a shape-init type the paper never defined).
UNUSED_OPCODES = (0b010, 0b100, 0b110, 0b111)


class Func(IntEnum):
    """F-type function in bits 10:9."""

    ER = 0b00
    NR = 0b01
    NF = 0b10
    LR = 0b11


@dataclass(frozen=True)
class Field:
    """A bit field ``word[hi:lo]``."""

    hi: int
    lo: int
    _low_mask: int = field(init=False, repr=False, compare=False)  # decode runs per word: precomputed

    def __post_init__(self) -> None:
        object.__setattr__(self, "_low_mask", (1 << self.width) - 1)

    @property
    def width(self) -> int:
        return self.hi - self.lo + 1

    @property
    def mask(self) -> int:
        return self._low_mask << self.lo

    def get(self, word: int) -> int:
        return (word >> self.lo) & self._low_mask

    def put(self, value: int) -> int:
        if not 0 <= value < (1 << self.width):
            raise ValueError(f"value {value} does not fit {self.width}-bit field [{self.hi}:{self.lo}]")
        return value << self.lo


OPCODE = Field(2, 0)
FUNC = Field(10, 9)
DATA = Field(31, 16)  # C and L
PROP = Field(15, 11)  # C, L and SE
LIGHT_INDEX = Field(8, 3)
SE_INDEX_HI = Field(31, 16)  # index[18:3]
SE_PROP2 = Field(10, 6)
SE_INDEX_LO = Field(5, 3)  # index[2:0]
SD_DATA = Field(31, 16)  # value for prop
SD_DATA2 = Field(15, 0)  # value for prop2

#: Bits that must be zero in each type, for a word to be canonical.
F_ZERO_MASK = 0xFFFFFFFF & ~(FUNC.mask | OPCODE.mask)
C_ZERO_MASK = 0x000007F8  # bits 10:3
L_ZERO_MASK = 0x00000600  # bits 10:9

LIGHT_INDEX_LIMIT = 1 << LIGHT_INDEX.width  # 64
SHAPE_INDEX_LIMIT = 1 << 19  # 524,288
PROP_LIMIT = 1 << PROP.width  # 32 property slots per table


class ValueType(Enum):
    """How a property's 16-bit field is interpreted."""

    ZERO = "n/a"  # the null property: writes nothing, its data is ignored
    FLOAT16 = "float16"
    INT = "int"


@dataclass(frozen=True)
class Property:
    """One row of a property table."""

    index: int
    name: str  # symbolic name, canonical spelling
    title: str  # the paper's long name
    vtype: ValueType
    bits: int = 16  # for INT: how many low bits carry the value
    extra_names: tuple[str, ...] = ()  # accepted spellings besides name and aN

    @property
    def register(self) -> str:
        return f"a{self.index}"

    @property
    def names(self) -> tuple[str, ...]:
        return (self.name, self.register, *self.extra_names)

    @property
    def value_mask(self) -> int:
        """The bits of the 16-bit field the device reads (INT: its low ``bits``)."""
        return (1 << self.bits) - 1

    @property
    def type_label(self) -> str:
        if self.vtype is ValueType.INT:
            return f"int{self.bits}"
        return self.vtype.value


class Table(Enum):
    """The four property tables; a value names the table in docs and messages."""

    CAMERA = "camera"
    LIGHT = "light"
    SHAPE = "shape"
    TRIANGLE = "triangle"


def _f(index: int, name: str, title: str, *extra: str) -> Property:
    return Property(index, name, title, ValueType.FLOAT16, 16, extra)


def _i(index: int, name: str, title: str, bits: int) -> Property:
    return Property(index, name, title, ValueType.INT, bits)


_ZERO = Property(0, "zero", "zero", ValueType.ZERO)
#: Location and quaternion rotation: indices 1-7 of both the camera and the shape table.
_PLACEMENT = (
    _f(1, "xloc", "x-location"),
    _f(2, "yloc", "y-location"),
    _f(3, "zloc", "z-location"),
    _f(4, "rrot", "rotation-r"),
    _f(5, "irot", "rotation-i", "iro"),
    _f(6, "jrot", "rotation-j"),
    _f(7, "krot", "rotation-k"),
)

PROPERTIES: dict[Table, tuple[Property, ...]] = {
    Table.CAMERA: (
        _ZERO,
        *_PLACEMENT,
        _f(8, "nclip", "near-clip"),
        _f(9, "fclip", "far-clip"),
        _f(10, "hfov", "fov-horizontal"),
        _f(11, "vfov", "fov-vertical"),
    ),
    Table.LIGHT: (
        _i(0, "src", "source type", 2),
        _f(1, "xloc", "x-location"),
        _f(2, "yloc", "y-location"),
        _f(3, "zloc", "z-location"),
        _f(4, "xfor", "x-forward"),
        _f(5, "yfor", "y-forward"),
        _f(6, "zfor", "z-forward"),
        _i(7, "col", "color", 16),
        _f(8, "int", "intensity"),
    ),
    Table.SHAPE: (
        _ZERO,
        *_PLACEMENT,
        _f(8, "xscl", "x-scale-inv"),
        _f(9, "yscl", "y-scale-inv"),
        _f(10, "zscl", "z-scale-inv"),
        _i(11, "col", "color", 16),
        _i(12, "mat", "material", 2),
        _i(13, "type", "shape type", 4),
    ),
    Table.TRIANGLE: (
        _ZERO,
        _f(1, "x1", "x1"),
        _f(2, "y1", "y1"),
        _f(3, "z1", "z1"),
        _f(4, "x2", "x2"),
        _f(5, "y2", "y2"),
        _f(6, "z2", "z2"),
        _f(7, "x3", "x3"),
        _f(8, "y3", "y3"),
        _f(9, "z3", "z3"),
        # index 10 is unused in the triangle table
        _i(11, "col", "color", 16),
        _i(12, "mat", "material", 2),
    ),
}

#: Which table each mnemonic's property operands name.
MNEMONIC_TABLE: dict[str, Table] = {"cam": Table.CAMERA, "lt": Table.LIGHT, "sp": Table.SHAPE, "tr": Table.TRIANGLE}

F_MNEMONICS: dict[str, Func] = {"er": Func.ER, "nr": Func.NR, "nf": Func.NF, "lr": Func.LR}

#: Light source types (low 2 bits of ``src``) and shape types (``type``).
LIGHT_SOURCES = {0: "off", 1: "directional", 2: "point"}
SHAPE_TYPES = {0: "off", 1: "sphere", 2: "cylinder", 3: "cone"}
LIGHT_SOURCE_CODES = {name: code for code, name in LIGHT_SOURCES.items()}
SHAPE_TYPE_CODES = {name: code for code, name in SHAPE_TYPES.items()}


#: Unused slots the original device's Python assembler (in its public repository) still
#: named, so its sources can use them: writable like a float16 property, ignored by
#: the device. Not in ``PROPERTIES``: the decoder, disassembler and emulator know no such
#: property, and ``aN`` does not name them.
ORIGINAL_NAMES: dict[Table, dict[str, Property]] = {t: {} for t in Table}
ORIGINAL_NAMES[Table.TRIANGLE]["none"] = Property(10, "none", "unused", ValueType.FLOAT16)


def by_index(table: Table) -> dict[int, Property]:
    """Properties of ``table`` keyed by index (gaps such as triangle 10 are absent)."""
    return _BY_INDEX[table]


def lookup(table: Table, name: str) -> Property | None:
    """Find a property by symbolic name, register alias or accepted spelling (any case)."""
    return _BY_NAME[table].get(name.lower())


_BY_INDEX = {t: {p.index: p for p in props} for t, props in PROPERTIES.items()}
_BY_NAME = {t: {n: p for p in props for n in p.names} for t, props in PROPERTIES.items()}
