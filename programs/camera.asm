; camera.asm: camera moved, rotated, field of view and clip planes changed.
;
; Shows:  every camera property. A row of five spheres runs along -z from z = -4 to
;         z = -20 at x = 0. The camera stands at (3, 1.5, 0), turned 12 degrees to the
;         left (about +y) and tilted 5 degrees down (about x), with the field of view
;         narrowed to 0.2 of the default in both axes; the near clip plane is 4.5 units
;         ahead (it cuts into the nearest sphere) and the far clip 13, so the spheres
;         beyond 13 units are not drawn.
; Run:    rend3r emulate programs/camera.asm -o out/camera.png
; Look:   orange-to-yellow spheres in a row from the lower left towards the centre. The
;         nearest, cut open by the near clip plane, shows only a thin lit crescent along
;         its upper and right edge (its inside is black); the next two are whole and
;         shrink into the distance; the two beyond the far clip plane are not drawn. In
;         fp16 the edges of the two whole spheres are ragged; fp64 draws them smooth.
; frames: 1

nr
cam zero, 0
cam xloc, 3
cam yloc, 1.5
cam zloc, 0
cam rrot, 0.99357                ; q = rot(y, 12 deg) * rot(x, -5 deg)
cam irot, -0.04338
cam jrot, 0.10443
cam krot, 0.00456
cam nclip, 4.5
cam fclip, 13
cam hfov, 0.2
cam vfov, 0.2

lt 0, src, 1
lt 0, xfor, -0.5
lt 0, yfor, -1
lt 0, zfor, -0.5
lt 0, col, 0xFFFF
lt 0, int, 1

.rept 5, i
sp i, type, col, 1, 0b11111_101000_00100 + i * 0b00000_000100_00110
sp i, xloc, yloc, 0, 0
sp i, zloc, rrot, -4 - 4 * i, 1
sp i, xscl, yscl, 1, 1
sp i, zscl, mat, 1, 0
.endr

nf
er
er
