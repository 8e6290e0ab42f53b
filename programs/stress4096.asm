; stress4096.asm: 4,096 shapes.
;
; Shows:  the paper's largest Table IV workload: 4,096 spheres (radius 0.45, 1 apart) in
;         an 8 x 8 grid of columns 64 spheres deep, the front layer 5 units ahead,
;         written with nested .rept; shape index = 64 * (8 * row + column) + depth.
;         Red grows along x, green along y, blue fades with depth. One directional light, so
;         every hit also casts a shadow ray against the 4,095 other shapes. The visible
;         spheres are kept large compared with their distance: a wall of 64 x 64 tiny
;         spheres would lose most of them to float16 cancellation in the quadratic (see
;         docs/numerics.md and fp16_cancel.asm).
; Run:    rend3r emulate programs/stress4096.asm -o out/stress4096.png --stats
; Look:   an 8 x 8 block of shaded beads lit from the upper right: blue at the lower
;         left, magenta at the lower right, cyan at the upper left, pale lavender at the
;         upper right; slivers of the spheres behind show through the gaps. In fp16 every
;         bead's edge is ragged and its face hatched with diagonal streaks; fp64 draws
;         them smooth.
; frames: 1
; test-size: 64x48

nr
cam rrot, 1
cam hfov, 0.225         ; field of view: 0.225 of the default 10 x 7.5 viewport
cam vfov, 0.225
lt 0, src, 1
lt 0, xfor, -0.3
lt 0, yfor, -0.3
lt 0, zfor, -1
lt 0, col, 0xFFFF
lt 0, int, 1

.rept 8, J
.rept 8, I
.rept 32, K
.rept 2, k
sp 64 * (8 * J + I) + 2 * K + k, type, col, 1, 8192 * I + 256 * J + 31 - K
sp 64 * (8 * J + I) + 2 * K + k, xloc, yloc, I - 3.5, J - 3.5
sp 64 * (8 * J + I) + 2 * K + k, zloc, rrot, -5 - 2 * K - k, 1
sp 64 * (8 * J + I) + 2 * K + k, xscl, yscl, 1 / 0.45, 1 / 0.45
sp 64 * (8 * J + I) + 2 * K + k, zscl, mat, 1 / 0.45, 0
.endr
.endr
.endr
.endr

nf
er
er
