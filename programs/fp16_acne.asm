; fp16_acne.asm: acne and z-fighting between almost coincident surfaces.
;
; Shows:  a green sphere of radius 1.503 around a red sphere of radius 1.5 (same centre).
;         Exactly, the green one is always nearer and nothing shadows it on its lit side.
;         In float16 the hit point is rounded (about 0.002 at these coordinates), so a
;         shadow ray can start inside the red sphere and report a shadow (acne), and the
;         nearest-hit comparison of two almost equal squared distances picks the red
;         sphere at some pixels (z-fighting).
; Run:    rend3r emulate programs/fp16_acne.asm -o out/fp16_acne.png
; Look:   fp16: a green sphere covered in concentric black rings and specks around a
;         black spot at its centre (a moire of rounding): where the red sphere wins it is
;         black, because the green shell around it shadows it; fp64: smooth green.
; frames: 1

nr
cam rrot, 1
cam hfov, 0.1
cam vfov, 0.1

lt 0, src, 1
lt 0, xfor, -0.7
lt 0, yfor, -0.7
lt 0, zfor, -1
lt 0, col, 0xFFFF
lt 0, int, 1

sp 0, type, col, 1, 0xF800        ; red, radius 1.5
sp 0, xloc, yloc, 0, 0
sp 0, zloc, rrot, -5, 1
sp 0, xscl, yscl, 1 / 1.5, 1 / 1.5
sp 0, zscl, mat, 1 / 1.5, 0

sp 1, type, col, 1, 0x07E0        ; green, radius 1.503
sp 1, xloc, yloc, 0, 0
sp 1, zloc, rrot, -5, 1
sp 1, xscl, yscl, 1 / 1.503, 1 / 1.503
sp 1, zscl, mat, 1 / 1.503, 0

nf
er
er
