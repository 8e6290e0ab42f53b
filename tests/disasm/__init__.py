"""Tests of the memory-image formats, the disassembler and the round trips."""
