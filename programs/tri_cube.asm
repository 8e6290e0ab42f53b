; tri_cube.asm: a cube of twelve triangles (rasterizer).
;
; Shows:  the triangle table: a cube of side 2 centred at (0, 0, -5), turned 25 degrees
;         about x then 35 degrees about y (vertices computed beforehand in float64 and
;         rounded to float16 by the assembler), two triangles per face, one colour per
;         face: +x red, -x cyan, +y green, -y magenta, +z blue, -z yellow. Triangles use
;         every material value 0..3 (materials do not change the image) and set the zero
;         property.
; Run:    rend3r emulate programs/tri_cube.asm --mode raster -o out/tri_cube.png
; Look:   three faces visible: blue (front, +z), green (top, +y) and cyan (left, -x),
;         each flat-shaded by the light from the upper left, with straight shared edges
;         and no gap between the two triangles of a face.
; frames: 1
; mode: raster

nr
cam rrot, 1
cam hfov, 0.25          ; field of view: 0.25 of the default 10 x 7.5 viewport
cam vfov, 0.25
lt 0, src, 1
lt 0, xfor, 0.3
lt 0, yfor, -0.6
lt 0, zfor, -1
lt 0, col, 0xFFFF
lt 0, int, 1

tr 0, x1, y1, 0.0569, -0.4837
tr 0, z1, x2, -6.6622, 0.5417
tr 0, y2, z2, 1.3289, -5.9698
tr 0, x3, y3, 1.5814, 0.4837
tr 0, z3, col, -4.485, 0xF800
tr 0, mat, zero, 0, 0
tr 1, x1, y1, 0.0569, -0.4837
tr 1, z1, x2, -6.6622, 1.5814
tr 1, y2, z2, 0.4837, -4.485
tr 1, x3, y3, 1.0966, -1.3289
tr 1, z3, col, -5.1774, 0xF800
tr 2, x1, y1, -0.5417, -1.3289
tr 2, z1, x2, -4.0302, -0.0569
tr 2, y2, z2, 0.4837, -3.3378
tr 2, x3, y3, -1.0966, 1.3289
tr 2, z3, col, -4.8226, 0x07FF
tr 2, mat, zero, 2, 0
tr 3, x1, y1, -0.5417, -1.3289
tr 3, z1, x2, -4.0302, -1.0966
tr 3, y2, z2, 1.3289, -4.8226
tr 3, x3, y3, -1.5814, -0.4837
tr 3, z3, col, -5.515, 0x07FF
tr 4, x1, y1, -1.0966, 1.3289
tr 4, z1, x2, -4.8226, -0.0569
tr 4, y2, z2, 0.4837, -3.3378
tr 4, x3, y3, 1.5814, 0.4837
tr 4, z3, col, -4.485, 0x07E0
tr 4, mat, zero, 0, 0
tr 5, x1, y1, -1.0966, 1.3289
tr 5, z1, x2, -4.8226, 1.5814
tr 5, y2, z2, 0.4837, -4.485
tr 5, x3, y3, 0.5417, 1.3289
tr 5, z3, col, -5.9698, 0x07E0
tr 6, x1, y1, 0.0569, -0.4837
tr 6, z1, x2, -6.6622, 1.0966
tr 6, y2, z2, -1.3289, -5.1774
tr 6, x3, y3, -0.5417, -1.3289
tr 6, z3, col, -4.0302, 0xF81F
tr 6, mat, zero, 2, 0
tr 7, x1, y1, 0.0569, -0.4837
tr 7, z1, x2, -6.6622, -0.5417
tr 7, y2, z2, -1.3289, -4.0302
tr 7, x3, y3, -1.5814, -0.4837
tr 7, z3, col, -5.515, 0xF81F
tr 8, x1, y1, -0.5417, -1.3289
tr 8, z1, x2, -4.0302, 1.0966
tr 8, y2, z2, -1.3289, -5.1774
tr 8, x3, y3, 1.5814, 0.4837
tr 8, z3, col, -4.485, 0x001F
tr 8, mat, zero, 0, 0
tr 9, x1, y1, -0.5417, -1.3289
tr 9, z1, x2, -4.0302, 1.5814
tr 9, y2, z2, 0.4837, -4.485
tr 9, x3, y3, -0.0569, 0.4837
tr 9, z3, col, -3.3378, 0x001F
tr 10, x1, y1, -1.0966, 1.3289
tr 10, z1, x2, -4.8226, 0.5417
tr 10, y2, z2, 1.3289, -5.9698
tr 10, x3, y3, 0.0569, -0.4837
tr 10, z3, col, -6.6622, 0xFFE0
tr 10, mat, zero, 2, 0
tr 11, x1, y1, -1.0966, 1.3289
tr 11, z1, x2, -4.8226, 0.0569
tr 11, y2, z2, -0.4837, -6.6622
tr 11, x3, y3, -1.5814, -0.4837
tr 11, z3, col, -5.515, 0xFFE0

nf
er
er
