; fp16_limits.asm: values at the edges of float16.
;
; Shows:  shapes that must not crash or poison the image: a sphere at x = 65504 (the
;         largest float16) behind the camera's view; a sphere with an all-zero rotation
;         quaternion; a sphere whose inverse scale is 65504 (radius 1.5e-5, and the
;         scaled ray overflows); a bar whose x inverse scale 3e-5 is a float16 subnormal
;         (flushed to zero with --subnormals ftz, kept with ieee; both make it effectively
;         infinite along x); a sphere with a non-unit quaternion (2, 0, 0, 0); and a
;         background sphere of radius 30000 whose centre is 60000 units away (its
;         distance overflows in float16).
; Run:    rend3r emulate programs/fp16_limits.asm -o out/fp16_limits.png
;         (compare --precision fp64 and --subnormals ieee)
; Look:   fp16: a red sphere (the zero quaternion reads as no rotation) above a
;         horizontal cyan bar across the screen; the non-unit-quaternion sphere is lost
;         too (|q|^2 = 4 scales its object coordinates until b*b overflows). fp64 also
;         draws it, small and yellow, and the huge far sphere as a grey backdrop.
; frames: 1

nr
cam rrot, 1
cam hfov, 0.25
cam vfov, 0.25
lt 0, src, 1
lt 0, xfor, -0.5
lt 0, yfor, -1
lt 0, zfor, -1
lt 0, col, 0xFFFF
lt 0, int, 1

sp 0, type, col, 1, 0xFFFF        ; at the float16 limit, outside the view
sp 0, xloc, yloc, 65504, 0
sp 0, zloc, rrot, -5, 1
sp 0, xscl, yscl, 1, 1
sp 0, zscl, mat, 1, 0

sp 1, type, col, 1, 0xF800        ; all-zero quaternion (rotation never set)
sp 1, xloc, yloc, -2, 1
sp 1, zloc, zero, -6, 0
sp 1, xscl, yscl, 1.5, 1.5
sp 1, zscl, mat, 1.5, 0

sp 2, type, col, 1, 0x07E0        ; inverse scale 65504: radius 1.5e-5, overflows
sp 2, xloc, yloc, 0, 1
sp 2, zloc, rrot, -6, 1
sp 2, xscl, yscl, 65504, 65504
sp 2, zscl, mat, 65504, 0

sp 3, type, col, 1, 0x07FF        ; subnormal x inverse scale: a bar along x
sp 3, xloc, yloc, 0, -1.2
sp 3, zloc, rrot, -7, 1
sp 3, xscl, yscl, 3e-5, 3
sp 3, zscl, mat, 3, 0

sp 4, type, col, 1, 0xFFE0        ; non-unit quaternion (2, 0, 0, 0)
sp 4, xloc, yloc, 2, 1
sp 4, zloc, rrot, -6, 2
sp 4, xscl, yscl, 1.5, 1.5
sp 4, zscl, mat, 1.5, 0

sp 5, type, col, 1, 0b01000_010000_01000  ; radius 30000, 60000 away
sp 5, xloc, yloc, 0, 0
sp 5, zloc, rrot, -60000, 1
sp 5, xscl, yscl, 1 / 30000, 1 / 30000
sp 5, zscl, mat, 1 / 30000, 0

nf
er
er
