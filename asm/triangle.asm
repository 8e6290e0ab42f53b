// Every triangle property by name and alias, as prop and as prop2; index extremes.
// SE: index[18:3] 31:16, prop 15:11, prop2 10:6, index[2:0] 5:3, opcode 101; SD: data 31:16, data2 15:0.
tr 0, zero, x1, 0, 0.25             ; => 0x00000045 0x00003400
tr 524287, zero, a1, 0, 100         ; => 0xffff007d 0x00005640
tr 5, a0, a1, 0, -0.125             ; => 0x0000006d 0x0000b000
tr 8, x1, y1, -0.125, 3             ; => 0x00010885 0xb0004200
tr 0, x1, a2, 3, 1.5                ; => 0x00000885 0x42003e00
tr 524287, a1, a2, 1.5, -2          ; => 0xffff08bd 0x3e00c000
tr 5, y1, z1, -2, 0.25              ; => 0x000010ed 0xc0003400
tr 8, y1, a3, 0.25, 100             ; => 0x000110c5 0x34005640
tr 0, a2, a3, 100, -0.125           ; => 0x000010c5 0x5640b000
tr 524287, z1, x2, -0.125, 3        ; => 0xffff193d 0xb0004200
tr 5, z1, a4, 3, 1.5                ; => 0x0000192d 0x42003e00
tr 8, a3, a4, 1.5, -2               ; => 0x00011905 0x3e00c000
tr 0, x2, y2, -2, 0.25              ; => 0x00002145 0xc0003400
tr 524287, x2, a5, 0.25, 100        ; => 0xffff217d 0x34005640
tr 5, a4, a5, 100, -0.125           ; => 0x0000216d 0x5640b000
tr 8, y2, z2, -0.125, 3             ; => 0x00012985 0xb0004200
tr 0, y2, a6, 3, 1.5                ; => 0x00002985 0x42003e00
tr 524287, a5, a6, 1.5, -2          ; => 0xffff29bd 0x3e00c000
tr 5, z2, x3, -2, 0.25              ; => 0x000031ed 0xc0003400
tr 8, z2, a7, 0.25, 100             ; => 0x000131c5 0x34005640
tr 0, a6, a7, 100, -0.125           ; => 0x000031c5 0x5640b000
tr 524287, x3, y3, -0.125, 3        ; => 0xffff3a3d 0xb0004200
tr 5, x3, a8, 3, 1.5                ; => 0x00003a2d 0x42003e00
tr 8, a7, a8, 1.5, -2               ; => 0x00013a05 0x3e00c000
tr 0, y3, z3, -2, 0.25              ; => 0x00004245 0xc0003400
tr 524287, y3, a9, 0.25, 100        ; => 0xffff427d 0x34005640
tr 5, a8, a9, 100, -0.125           ; => 0x0000426d 0x5640b000
tr 8, z3, col, -0.125, 65534        ; => 0x00014ac5 0xb000fffe
tr 0, z3, a11, 3, 65535             ; => 0x00004ac5 0x4200ffff
tr 524287, a9, a11, 1.5, 65534      ; => 0xffff4afd 0x3e00fffe
tr 5, col, mat, 65534, 3            ; => 0x00005b2d 0xfffe0003
tr 8, col, a12, 65535, 2            ; => 0x00015b05 0xffff0002
tr 0, a11, a12, 65534, 3            ; => 0x00005b05 0xfffe0003
tr 524287, mat, zero, 3, 0          ; => 0xffff603d 0x00030000
tr 5, mat, a0, 2, 0                 ; => 0x0000602d 0x00020000
tr 8, a12, a0, 3, 0                 ; => 0x00016005 0x00030000
tr 524288, x1, y1, 1, 1             ; error: triangle index 524288 is out of range (0..524287)
tr 0, a10, x1, 1, 1                 ; error: the triangle table has no property 10
tr 0, type, x1, 1, 1                ; error: unknown triangle property 'type'
er                                  ; => 0x00000000
er                                  ; => 0x00000000
