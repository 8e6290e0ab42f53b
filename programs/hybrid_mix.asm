; hybrid_mix.asm: analytic shapes and triangles in one frame (--mode hybrid).
;
; Shows:  the TS table-select extension (docs/isa-extensions.md), enabled by the
;         `.isa_ext hybrid` line below: `ts shape` routes the following sp pairs to the
;         shape table, `ts triangle` routes tr pairs to the triangle table. Each nf
;         raytraces the shapes, rasterizes the triangles through the same camera and
;         keeps the nearer surface per pixel. A triangle floor and an orange pyramid of
;         four triangles; a red sphere that pierces the pyramid's left face and a blue
;         one in front of it at the right. Triangles are flat-shaded and take no shadows.
; Run:    rend3r emulate programs/hybrid_mix.asm --mode hybrid -o out/hybrid_mix.png
; Look:   a grey triangle floor ending in a straight far edge, the orange front face of
;         the pyramid, the red sphere half hidden behind it where it pierces the face, the
;         small blue sphere in front at the right (in fp16 its lower edge is ragged).
; frames: 1
; mode: hybrid

.isa_ext hybrid                  ; accept ts (no assembler flag needed)
nr
cam rrot, 1
cam hfov, 0.25
cam vfov, 0.25
lt 0, src, 1
lt 0, xfor, -0.4
lt 0, yfor, -1
lt 0, zfor, -0.6
lt 0, col, 0xFFFF
lt 0, int, 1

ts shape                         ; sp pairs write the shape table
sp 0, type, col, 1, 0b11111_000100_00100   ; red sphere piercing the pyramid
sp 0, xloc, yloc, -0.7, -0.1
sp 0, zloc, rrot, -5.5, 1
sp 0, xscl, yscl, 1 / 0.7, 1 / 0.7
sp 0, zscl, mat, 1 / 0.7, 0
sp 1, type, col, 1, 0b00100_010000_11111   ; blue sphere in front, right
sp 1, xloc, yloc, 1.5, -0.55
sp 1, zloc, rrot, -3.6, 1
sp 1, xscl, yscl, 1 / 0.45, 1 / 0.45
sp 1, zscl, mat, 1 / 0.45, 0

ts triangle                      ; tr pairs write the triangle table
; 0-1: floor at y = -1; 2-5: pyramid faces (wound counter-clockwise from outside)
tr 0, x1, y1, -4, -1
tr 0, z1, x2, -2, 4
tr 0, y2, z2, -1, -2
tr 0, x3, y3, 4, -1
tr 0, z3, col, -10, 0x630C
tr 1, x1, y1, -4, -1
tr 1, z1, x2, -2, 4
tr 1, y2, z2, -1, -10
tr 1, x3, y3, -4, -1
tr 1, z3, col, -10, 0x630C
tr 2, x1, y1, -0.8, -1
tr 2, z1, x2, -4.3, 1.6
tr 2, y2, z2, -1, -4.3
tr 2, x3, y3, 0.4, 1.2
tr 2, z3, col, -5.5, 0xFE00
tr 3, x1, y1, 1.6, -1
tr 3, z1, x2, -4.3, 1.6
tr 3, y2, z2, -1, -6.7
tr 3, x3, y3, 0.4, 1.2
tr 3, z3, col, -5.5, 0xFC00
tr 4, x1, y1, 1.6, -1
tr 4, z1, x2, -6.7, -0.8
tr 4, y2, z2, -1, -6.7
tr 4, x3, y3, 0.4, 1.2
tr 4, z3, col, -5.5, 0xFE00
tr 5, x1, y1, -0.8, -1
tr 5, z1, x2, -6.7, -0.8
tr 5, y2, z2, -1, -4.3
tr 5, x3, y3, 0.4, 1.2
tr 5, z3, col, -5.5, 0xFC00

nf
er
er
