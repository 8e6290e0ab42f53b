; fp16_distance.asm: the float16 distance overflow at 256 units.
;
; Shows:  the squared hit distance |d|^2 * t^2 is a float16 and overflows (> 65504) once a
;         surface is more than about 256 units away; the ray then counts as a miss. Three
;         spheres of radius 50 whose centres are 220, 290 and 360 units from the camera
;         (narrow field of view, 0.15 of the default; the near clip at 100 makes the
;         unnormalised ray directions 100 long, so nothing underflows, see
;         fp16_underflow.asm).
; Run:    rend3r emulate programs/fp16_distance.asm -o out/fp16_distance.png
;         (compare --precision fp32, which draws all three)
; Look:   fp16: the left sphere whole, with a ragged top edge and faint seams where its
;         shading steps; of the middle one only a central disc (the part nearer than 256
;         units) with a square patch at its middle; the right one missing. fp32/fp64:
;         three whole spheres.
; frames: 1

nr
cam rrot, 1
cam hfov, 0.15
cam vfov, 0.15
cam nclip, 100                  ; long ray directions: see fp16_underflow.asm

lt 0, src, 1
lt 0, xfor, -0.5
lt 0, yfor, -0.5
lt 0, zfor, -1
lt 0, col, 0xFFFF
lt 0, int, 1

.rept 3, i
sp i, type, col, 1, 0b11100_110000_00110 - i * 0b00000_010000_00000
sp i, yloc, rrot, 0, 1
sp i, xscl, yscl, 0.02, 0.02
sp i, zscl, mat, 0.02, 0
.endr
sp 0, xloc, zloc, -110, -190.526
sp 1, xloc, zloc, 0, -290
sp 2, xloc, zloc, 110, -342.783

nf
er
er
