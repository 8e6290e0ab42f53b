; fp16_cancel.asm: cancellation in the quadratic for small, distant spheres.
;
; Shows:  the ray-sphere discriminant b^2 - a2*c2 subtracts two nearly equal numbers when a
;         sphere is far away compared with its radius (S = distance / radius): both terms
;         grow like S^2 while their difference stays of order 1, so float16's 11-bit
;         significand leaves few or no correct bits. Left: a sphere at S = 16; right: one
;         at S = 32. A very narrow field of view (0.03 of the default) makes them large.
; Run:    rend3r emulate programs/fp16_cancel.asm -o out/fp16_cancel.png
; Look:   fp16: each sphere broken into vertical crescent-shaped slices with black gaps
;         between them, each slice shaded flat, the right (blue) sphere far worse than the
;         left (orange); fp32/fp64: two smooth shaded spheres.
; frames: 1

nr
cam rrot, 1
cam hfov, 0.03
cam vfov, 0.03

lt 0, src, 1
lt 0, xfor, -0.6
lt 0, yfor, -0.6
lt 0, zfor, -1
lt 0, col, 0xFFFF
lt 0, int, 1

sp 0, type, col, 1, 0b11111_101000_00000
sp 0, xloc, yloc, -1.2, 0
sp 0, zloc, rrot, -16, 1
sp 0, xscl, yscl, 1, 1
sp 0, zscl, mat, 1, 0

sp 1, type, col, 1, 0b00000_101000_11111
sp 1, xloc, yloc, 2.4, 0
sp 1, zloc, rrot, -32, 1
sp 1, xscl, yscl, 1, 1
sp 1, zscl, mat, 1, 0

nf
er
er
