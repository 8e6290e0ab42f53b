; fp16_underflow.asm: squared terms that underflow, flushed to zero.
;
; Shows:  a sphere of radius 20 centred 100 units ahead (inverse scale 0.05) seen with a
;         narrow field of view (0.3 of the default) and the default near clip 1, so ray
;         directions are about 1 long and shrink to about 0.05 in object space. Their
;         squares (x*x, y*y) fall below float16's smallest normal 6.1e-5 wherever
;         |x| or |y| < 0.156: with --subnormals ftz (the device's vendor IP) they become 0,
;         the quadratic's a shrinks and the sphere grows along those bands. With
;         --subnormals ieee the subnormals keep enough bits and the disc stays round.
; Run:    rend3r emulate programs/fp16_underflow.asm -o out/fp16_underflow.png
;         (compare --subnormals ieee and --precision fp64)
; Look:   fp16 ftz: not a disc but a purple square with stepped corners, two overlapping
;         rectangles (a cross of wider bands through the centre): where both squared
;         components vanish the corners stay square; fp16 ieee and fp64: a round disc.
; frames: 1

nr
cam rrot, 1
cam hfov, 0.3
cam vfov, 0.3

lt 0, src, 1
lt 0, xfor, -0.5
lt 0, yfor, -0.5
lt 0, zfor, -1
lt 0, col, 0xFFFF
lt 0, int, 1

sp 0, type, col, 1, 0b10100_010000_11111
sp 0, xloc, yloc, 0, 0
sp 0, zloc, rrot, -100, 1
sp 0, xscl, yscl, 0.05, 0.05
sp 0, zscl, mat, 0.05, 0

nf
er
er
