; tri_overlap.asm: overlapping and interpenetrating triangles (rasterizer).
;
; Shows:  depth between triangles. A red triangle at z = -4 is written first, a green one
;         at z = -6 (farther, larger) second, so drawing in program order alone would paint
;         green over red; a blue triangle tilted in depth (z from -3 to -7) pierces both.
;         The two triangles sharing the edge at the bottom are given in opposite windings.
; Run:    rend3r emulate programs/tri_overlap.asm --mode raster -o out/tri_overlap.png
; Look:   red in front of green where they overlap; the blue sliver, narrow at the left
;         screen edge and widening to the right as it tilts away, passes behind the red
;         triangle and in front of the green one until it pierces it near the green one's
;         right edge (a short stretch of blue hidden there); a yellow/cyan pair of
;         triangles at the bottom joined without a gap.
; frames: 1
; mode: raster

nr
cam rrot, 1
cam hfov, 0.25          ; field of view: 0.25 of the default 10 x 7.5 viewport
cam vfov, 0.25

; 0: red, near
tr 0, x1, y1, -2, -1
tr 0, z1, x2, -4, 1
tr 0, y2, z2, -1, -4
tr 0, x3, y3, -0.5, 1.5
tr 0, z3, col, -4, 0xF800
; 1: green, far and large
tr 1, x1, y1, -1, -3
tr 1, z1, x2, -6, 4
tr 1, y2, z2, -2, -6
tr 1, x3, y3, 1, 3
tr 1, z3, col, -6, 0x07E0
; 2: blue, slanted through both
tr 2, x1, y1, -4, 0.2
tr 2, z1, x2, -3, 4
tr 2, y2, z2, 0.6, -7
tr 2, x3, y3, 4, -0.2
tr 2, z3, col, -7, 0x001F
; 3 and 4: two triangles sharing an edge, opposite windings
tr 3, x1, y1, -2, -3.5
tr 3, z1, x2, -5, 0
tr 3, y2, z2, -2.5, -5
tr 3, x3, y3, 0, -4
tr 3, z3, col, -5, 0xFFE0
tr 4, x1, y1, 0, -2.5
tr 4, z1, x2, -5, 0
tr 4, y2, z2, -4, -5
tr 4, x3, y3, 2, -3.5
tr 4, z3, col, -5, 0x07FF

nf
er
er
