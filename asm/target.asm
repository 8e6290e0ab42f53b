// Indices and sizes beyond a device build's memories (rend3r-raytracing: 2 shapes,
// 2 lights, 2 triangles, 32 instructions) are warnings: the device aliases indices.
;! target rend3r-raytracing
;! file-warning: program is 35 words; rend3r-raytracing holds 32
lt 1, xloc, 1                        ; => 0x3c00080b
lt 2, xloc, 1                        ; => 0x3c000813 ; warning: light index 2 is beyond rend3r-raytracing's 2 light slots (the device aliases it to 0)
sp 1, xloc, yloc, 1, 1               ; => 0x0000088d 0x3c003c00
sp 5, xloc, yloc, 1, 1               ; => 0x000008ad 0x3c003c00 ; warning: shape index 5 is beyond rend3r-raytracing's 2 shape slots (the device aliases it to 1)
tr 2, x1, y1, 1, 1                   ; => 0x00000895 0x3c003c00 ; warning: triangle index 2 is beyond
.rept 12, i
  nr                                 ; => 0x00000200 0x00000200 0x00000200 0x00000200 0x00000200 0x00000200 0x00000200 0x00000200 0x00000200 0x00000200 0x00000200 0x00000200
.endr
.word 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0   ; => 0x00000000 0x00000000 0x00000000 0x00000000 0x00000000 0x00000000 0x00000000 0x00000000 0x00000000 0x00000000 0x00000000 0x00000000 0x00000000
er                                   ; => 0x00000000
er                                   ; => 0x00000000
