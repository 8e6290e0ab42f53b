"""Assembler, disassembler and memory-image formats for REND3R programs."""
