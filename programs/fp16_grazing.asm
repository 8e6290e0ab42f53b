; fp16_grazing.asm: rays along a cylinder's axis, a cone's apex, grazing rays, a light
; parallel to a surface.
;
; Shows:  a cylinder of radius 1 whose axis runs parallel to the view axis, 1.5 below
;         and right of it, so it recedes to the vanishing point at the screen centre: rays
;         near that point run almost parallel to the axis (the quadratic's a tends to 0)
;         and meet the surface farther and farther away. A slim double cone (radius a
;         quarter of the height) has its apex at (-2, 1.5, -8), up and to the left.
;         Light 0 travels exactly along the cylinder's axis, parallel to its surface
;         (n.l = 0, adds nothing to the cylinder); light 1 is a point light between
;         the two shapes.
; Run:    rend3r emulate programs/fp16_grazing.asm -o out/fp16_grazing.png
; Look:   a lavender pipe running from the lower right corner into the centre; an
;         orange hourglass pinched to a point at the upper left, its far nappe a disc
;         around the centre. In fp16 that disc's right and lower rim, more than 256 units
;         away, is missing (black; see fp16_distance.asm), and a few single pixels on the
;         surfaces are black.
; frames: 1

nr
cam rrot, 1
cam hfov, 0.25
cam vfov, 0.25

lt 0, src, 1                      ; along the cylinder axis: parallel to its surface
lt 0, xfor, 0
lt 0, yfor, 0
lt 0, zfor, -1
lt 0, col, 0b11111_111111_00000
lt 0, int, 1
lt 1, src, 2                      ; point light between the shapes
lt 1, xloc, 0
lt 1, yloc, 0
lt 1, zloc, -2
lt 1, col, 0xFFFF
lt 1, int, 1

sp 0, type, col, 2, 0b10000_100000_11111   ; cylinder along z, axis at (1.5, -1.5)
sp 0, xloc, yloc, 1.5, -1.5
sp 0, zloc, rrot, 0, 1
sp 0, xscl, yscl, 1, 1
sp 0, zscl, mat, 1, 0

sp 1, type, col, 3, 0b11111_011000_00000   ; cone, apex at (-2, 1.5, -8)
sp 1, xloc, yloc, -2, 1.5
sp 1, zloc, rrot, -8, 1
sp 1, xscl, yscl, 4, 4
sp 1, zscl, mat, 1, 0

nf
er
er
