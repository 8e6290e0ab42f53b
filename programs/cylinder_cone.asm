; cylinder_cone.asm: the two quadric shape types besides the sphere.
;
; Shows:  shape type 2 (cylinder x^2 + y^2 = 1, infinite along its z axis) and type 3
;         (double cone x^2 + y^2 = z^2). Both are turned 90 degrees about x so their axes
;         stand vertical on screen: quaternion (cos 45, sin 45, 0, 0).
; Run:    rend3r emulate programs/cylinder_cone.asm -o out/cylinder_cone.png
; Look:   on the left a green vertical band (the cylinder, radius 0.6) running off the top
;         and bottom of the screen; on the right an orange hourglass (the double cone,
;         apex at the centre height, opening 1:2). Both lit from the right. In fp16 the
;         cone's apex is a ragged notch of stair steps; fp64 draws a sharp point.
; frames: 1

C45 = 0.70710678                ; cos 45 = sin 45

nr
cam rrot, 1
cam hfov, 0.25          ; field of view: 0.25 of the default 10 x 7.5 viewport
cam vfov, 0.25

lt 0, src, 1
lt 0, xfor, -1
lt 0, yfor, -0.3
lt 0, zfor, -0.6
lt 0, col, 0xFFFF
lt 0, int, 1

; shape 0: cylinder, radius 0.6
sp 0, type, col, 2, 0b00000_111111_00000
sp 0, xloc, yloc, -1.6, 0
sp 0, zloc, rrot, -4, C45
sp 0, irot, jrot, C45, 0
sp 0, krot, mat, 0, 0
sp 0, xscl, yscl, 1 / 0.6, 1 / 0.6
sp 0, zscl, zero, 1, 0

; shape 1: cone; x, y inverse scale 2 against z 1 makes the radius grow half as fast as
; the height
sp 1, type, col, 3, 0b11111_100000_00000
sp 1, xloc, yloc, 1.6, 0
sp 1, zloc, rrot, -4, C45
sp 1, irot, jrot, C45, 0
sp 1, krot, mat, 0, 0
sp 1, xscl, yscl, 2, 2
sp 1, zscl, zero, 1, 0

nf
er
er
