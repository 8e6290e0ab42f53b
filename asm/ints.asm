// Int properties: range checks by field width, decimal/0x/0b with '_', raw 0h bypass.
// light src (2 bits, prop 0): word = v << 16 | 0x0003; light col (16 bits, prop 7): v << 16 | 0x3803
lt 0, src, 0                         ; => 0x00000003
lt 0, src, 3                         ; => 0x00030003
lt 0, src, 4                         ; error: 4 is out of range for 'src' (2 bits: 0..3)
lt 0, src, -1                        ; error: -1 is out of range for 'src'
lt 0, src, 1.5                       ; error: 'src' takes an integer or 0h raw bits, got 1.5
lt 0, src, 2.0                       ; => 0x00020003
lt 0, src, 6 / 3                     ; => 0x00020003
lt 0, src, -0                        ; => 0x00000003
lt 0, src, 0hffff                    ; => 0xffff0003
lt 0, col, 65535                     ; => 0xffff3803
lt 0, col, 0xffff                    ; => 0xffff3803
lt 0, col, 0XF800                    ; => 0xf8003803
lt 0, col, 0b11111_000000_00000      ; => 0xf8003803
lt 0, col, 0b00000_111111_00000      ; => 0x07e03803
lt 0, col, 0B00000_000000_11111      ; => 0x001f3803
lt 0, col, 0x1_0000                  ; error: 0x1_0000 = 65536 is out of range for 'col' (16 bits: 0..65535)
lt 0, col, 65536                     ; error: 65536 is out of range for 'col'
lt 0, col, 0x                        ; error: malformed hexadecimal number '0x'
lt 0, col, 0b102                     ; error: malformed binary number '0b102'
lt 0, col, 0x_ff                     ; error: malformed hexadecimal number '0x_ff'
// shape mat (2 bits, prop 12) and type (4 bits, prop 13): SE 0x00006345, SD mat << 16 | type
sp 0, mat, type, 3, 15               ; => 0x00006345 0x0003000f
sp 0, mat, type, 0, 0                ; => 0x00006345 0x00000000
sp 0, mat, type, 4, 1                ; error: 4 is out of range for 'mat' (2 bits: 0..3)
sp 0, mat, type, 1, 16               ; error: 16 is out of range for 'type' (4 bits: 0..15)
sp 0, mat, type, 0h1234, 0hffff      ; => 0x00006345 0x1234ffff
// the zero property takes any 16-bit integer or raw bits (the device ignores it)
sp 0, col, zero, 0x1234, 65535       ; => 0x00005805 0x1234ffff
sp 0, col, zero, 0, 0h0001           ; => 0x00005805 0x00000001
sp 0, col, zero, 0, 65536            ; error: 65536 is out of range for the zero property
sp 0, col, zero, 0, 0.5              ; error: the zero property takes an integer or 0h raw bits, got 0.5
cam zero, 7                          ; => 0x00070001
er                                   ; => 0x00000000
er                                   ; => 0x00000000
