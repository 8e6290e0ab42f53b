; shadow.asm: a small sphere casting a shadow on a large one.
;
; Shows:  shadow rays. A yellow sphere (radius 0.5) floats between the light and a big
;         blue sphere (radius 2); the light travels along (-0.4, -0.4, -1), which carries
;         the small sphere's centre onto the big sphere's centre.
; Run:    rend3r emulate programs/shadow.asm -o out/shadow.png
; Look:   a big blue disc lit from the upper right with a round black shadow on its face,
;         down and to the left of the small yellow disc that casts it (in fp16 the yellow
;         disc's right edge is ragged).
; frames: 1

nr
cam rrot, 1
cam hfov, 0.25          ; field of view: 0.25 of the default 10 x 7.5 viewport
cam vfov, 0.25

lt 0, src, 1
lt 0, xfor, -0.4
lt 0, yfor, -0.4
lt 0, zfor, -1
lt 0, col, 0xFFFF
lt 0, int, 1

; shape 0: the big blue sphere
sp 0, type, col, 1, 0b00000_011111_11111
sp 0, xloc, yloc, 0, 0
sp 0, zloc, rrot, -6, 1
sp 0, xscl, yscl, 0.5, 0.5
sp 0, zscl, mat, 0.5, 0

; shape 1: the small yellow sphere that casts the shadow
sp 1, type, col, 1, 0b11111_111111_00000
sp 1, xloc, yloc, 1, 1
sp 1, zloc, rrot, -3.5, 1
sp 1, xscl, yscl, 2, 2
sp 1, zscl, mat, 2, 0

nf
er
er
