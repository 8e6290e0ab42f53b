; fp16_grazing.asm: grazing rays, rays along a cylinder's axis, a cone's apex, a light
; parallel to a surface.
;
; Shows:  the camera inside a cylinder of radius 2 whose axis is the view axis (a tunnel):
;         rays nearly parallel to the axis meet the wall far away or, for the central
;         ray, never (a2 = 0). A double cone (opening 45 degrees) has its apex on the view
;         axis 6 units ahead. Light 0 travels exactly along the tunnel, parallel to its
;         wall (n.l = 0); light 1 is a point light inside the tunnel.
; Run:    rend3r emulate programs/fp16_grazing.asm -o fp16_grazing.png
; Look:   a tunnel lit by the point light, the cone's point at the centre of the screen
;         with its far nappe opening behind it; where the directional light alone reaches
;         the wall it adds nothing (black, not noise).
; frames: 1

nr
cam rrot, 1
cam hfov, 0.4
cam vfov, 0.4

lt 0, src, 1                      ; along the tunnel axis: parallel to the wall
lt 0, xfor, 0
lt 0, yfor, 0
lt 0, zfor, -1
lt 0, col, 0b11111_111111_00000
lt 0, int, 1
lt 1, src, 2                      ; point light inside the tunnel
lt 1, xloc, 1
lt 1, yloc, 1.2
lt 1, zloc, -3
lt 1, col, 0xFFFF
lt 1, int, 1

sp 0, type, col, 2, 0b10000_100000_11111   ; cylinder along z through the camera
sp 0, xloc, yloc, 0, 0
sp 0, zloc, rrot, 0, 1
sp 0, xscl, yscl, 0.5, 0.5
sp 0, zscl, mat, 1, 0

sp 1, type, col, 3, 0b11111_011000_00000   ; cone, apex at (0, 0, -6)
sp 1, xloc, yloc, 0, 0
sp 1, zloc, rrot, -6, 1
sp 1, xscl, yscl, 1, 1
sp 1, zscl, mat, 1, 0

nf
er
er
