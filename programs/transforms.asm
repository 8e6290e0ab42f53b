; transforms.asm: rotated and non-uniformly scaled shapes.
;
; Shows:  the per-shape transform: translate, rotate by the inverse quaternion, then the
;         inverse scales. Left: an ellipsoid stretched 2x along x and squashed to 0.5 along
;         y, rotated 30 degrees about z. Middle: a cylinder with an elliptical cross
;         section tilted 60 degrees about x and 20 about y (a non-unit quaternion, the raw
;         sum of the two, to show the emulator uses the given q as is). Right: a cone
;         turned 45 degrees about z then 90 about x.
; Run:    rend3r emulate programs/transforms.asm -o out/transforms.png
; Look:   the white double cone dominates: its near nappe a bright fan opening to the
;         lower right from an apex right of centre (frayed in fp16), its far nappe almost
;         black over the upper left, with a faint grey wedge running up to the top edge;
;         a cyan rod leans up from the bottom edge, left of the apex. The magenta
;         ellipsoid at the left does not show: the far nappe hides its upper half and its
;         lower half faces away from the light (from the upper left), so it is black on
;         black.
; frames: 1

nr
cam rrot, 1
cam hfov, 0.25          ; field of view: 0.25 of the default 10 x 7.5 viewport
cam vfov, 0.25

lt 0, src, 1
lt 0, xfor, 1
lt 0, yfor, -1
lt 0, zfor, -1
lt 0, col, 0xFFFF
lt 0, int, 1

; shape 0: ellipsoid, semi-axes 2 x 0.5 x 1, rotated 30 degrees about z
sp 0, type, col, 1, 0b11111_000000_11111
sp 0, xloc, yloc, -2.2, 0.6
sp 0, zloc, rrot, -5, 0.96592583   ; cos 15
sp 0, irot, jrot, 0, 0
sp 0, krot, mat, 0.25881905, 0     ; sin 15
sp 0, xscl, yscl, 0.5, 2
sp 0, zscl, zero, 1, 0

; shape 1: elliptic cylinder (semi-axes 0.4 x 0.8), q = (0.866, 0.5, 0.17, 0)
sp 1, type, col, 2, 0b00000_111111_11111
sp 1, xloc, yloc, 0.2, 0
sp 1, zloc, rrot, -6, 0.866
sp 1, irot, jrot, 0.5, 0.17
sp 1, krot, mat, 0, 0
sp 1, xscl, yscl, 2.5, 1.25
sp 1, zscl, zero, 1, 0

; shape 2: cone, q = rot(z, 45) * rot(x, 90) = (0.6533, 0.6533, 0.2706, 0.2706)
sp 2, type, col, 3, 0xFFFF
sp 2, xloc, yloc, 2.4, -0.4
sp 2, zloc, rrot, -5, 0.65328148
sp 2, irot, jrot, 0.65328148, 0.27059805
sp 2, krot, mat, 0.27059805, 0
sp 2, xscl, yscl, 1.5, 1.5
sp 2, zscl, zero, 1, 0

nf
er
er
