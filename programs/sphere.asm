; sphere.asm: one sphere, one directional light.
;
; Shows:  the basic raytrace: a red unit sphere 3 units in front of the camera (which looks
;         down -z from the origin), lit by a white directional light shining from the
;         upper right, behind the viewer.
; Run:    rend3r emulate programs/sphere.asm -o out/sphere.png
; Look:   a red disc in the middle of a black screen, brightest towards the upper right,
;         shading to black on the lower left where the surface faces away from the light.
; frames: 1

nr
cam rrot, 1                     ; identity camera rotation (the other parts stay 0)
cam hfov, 0.25          ; field of view: 0.25 of the default 10 x 7.5 viewport
cam vfov, 0.25

lt 0, src, 1                    ; light 0: directional ...
lt 0, xfor, -1                  ; ... travelling along (-1, -1, -1)
lt 0, yfor, -1
lt 0, zfor, -1
lt 0, col, 0b11111_111111_11111 ; white
lt 0, int, 1

sp 0, type, col, 1, 0b11111_000000_00000   ; sphere, red
sp 0, xloc, yloc, 0, 0
sp 0, zloc, rrot, -3, 1                    ; identity rotation
sp 0, xscl, yscl, 1, 1                     ; radius 1 (inverse scales 1)
sp 0, zscl, mat, 1, 0

nf
er
er
