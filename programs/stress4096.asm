; stress4096.asm: 4,096 shapes.
;
; Shows:  the paper's largest Table IV workload: a 64 x 64 grid of small spheres
;         (radius 0.2, 0.5 apart in x, 0.375 in y) at z = -4, written with nested .rept;
;         shape index = 64 * row + column. Red grows down the rows, blue across the
;         columns. One directional light, so every hit also casts a shadow ray against
;         4,095 other shapes.
; Run:    rend3r emulate programs/stress4096.asm -o stress4096.png --stats
; Look:   a lattice of small shaded beads filling most of the screen, black at the
;         upper left, red at the bottom, blue at the right, magenta at the lower right.
; frames: 1
; test-size: 64x48

nr
cam rrot, 1
lt 0, src, 1
lt 0, xfor, -0.3
lt 0, yfor, -0.3
lt 0, zfor, -1
lt 0, col, 0xFFFF
lt 0, int, 1

.rept 32, R
.rept 2, h
.rept 32, C
.rept 2, k
sp 64 * (2 * R + h) + 2 * C + k, type, col, 1, 2048 * R + 1024 + C
sp 64 * (2 * R + h) + 2 * C + k, xloc, yloc, (2 * C + k - 31.5) * 0.5, (31.5 - 2 * R - h) * 0.375
sp 64 * (2 * R + h) + 2 * C + k, zloc, rrot, -4, 1
sp 64 * (2 * R + h) + 2 * C + k, xscl, yscl, 5, 5
sp 64 * (2 * R + h) + 2 * C + k, zscl, mat, 5, 0
.endr
.endr
.endr
.endr

nf
er
er
