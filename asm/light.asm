// Every light property by name and alias; light index extremes 0 and 63.
// L-type: data 31:16, prop 15:11, bits 10:9 zero, index 8:3, opcode 011.
lt 0, src, 3                        ; => 0x00030003
lt 0, a0, 3                         ; => 0x00030003
lt 63, xloc, -2                     ; => 0xc00009fb
lt 63, a1, -2                       ; => 0xc00009fb
lt 17, yloc, 0.25                   ; => 0x3400108b
lt 17, a2, 0.25                     ; => 0x3400108b
lt 0, zloc, 100                     ; => 0x56401803
lt 0, a3, 100                       ; => 0x56401803
lt 63, xfor, -0.125                 ; => 0xb00021fb
lt 63, a4, -0.125                   ; => 0xb00021fb
lt 17, yfor, 3                      ; => 0x4200288b
lt 17, a5, 3                        ; => 0x4200288b
lt 0, zfor, 1.5                     ; => 0x3e003003
lt 0, a6, 1.5                       ; => 0x3e003003
lt 63, col, 65534                   ; => 0xfffe39fb
lt 63, a7, 65534                    ; => 0xfffe39fb
lt 17, int, 0.25                    ; => 0x3400408b
lt 17, a8, 0.25                     ; => 0x3400408b
lt 63, int, 1                       ; => 0x3c0041fb
lt 64, xloc, 1                      ; error: light index 64 is out of range (0..63)
lt -1, xloc, 1                      ; error: light index -1 is out of range (0..63)
lt 1.5, xloc, 1                     ; error: light index must be an integer, got 1.5
lt 0h1, xloc, 1                     ; error: light index must be an integer, not raw bits '0h1'
lt 0, type, 1                       ; error: unknown light property 'type'
er                                  ; => 0x00000000
er                                  ; => 0x00000000
