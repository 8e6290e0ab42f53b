// Every camera property by symbolic name, register alias and accepted spelling.
// C-type: data 31:16, prop 15:11, bits 10:3 zero, opcode 001.
cam zloc, -2                        ; => 0xc0001801
cam zero, 0                         ; => 0x00000001
cam a0, 0                           ; => 0x00000001
cam xloc, -2                        ; => 0xc0000801
cam a1, -2                          ; => 0xc0000801
cam yloc, 0.25                      ; => 0x34001001
cam a2, 0.25                        ; => 0x34001001
cam zloc, 100                       ; => 0x56401801
cam a3, 100                         ; => 0x56401801
cam rrot, -0.125                    ; => 0xb0002001
cam a4, -0.125                      ; => 0xb0002001
cam irot, 3                         ; => 0x42002801
cam a5, 3                           ; => 0x42002801
cam iro, 3                          ; => 0x42002801
cam jrot, 1.5                       ; => 0x3e003001
cam a6, 1.5                         ; => 0x3e003001
cam krot, -2                        ; => 0xc0003801
cam a7, -2                          ; => 0xc0003801
cam nclip, 0.25                     ; => 0x34004001
cam a8, 0.25                        ; => 0x34004001
cam fclip, 100                      ; => 0x56404801
cam a9, 100                         ; => 0x56404801
cam hfov, -0.125                    ; => 0xb0005001
cam a10, -0.125                     ; => 0xb0005001
cam vfov, 3                         ; => 0x42005801
cam a11, 3                          ; => 0x42005801
CAM XLOC, 1.5                       ; => 0x3e000801
cam A5, 1.5                         ; => 0x3e002801
cam IRO, 1.5                        ; => 0x3e002801
cam xlco, 1                         ; error: unknown camera property 'xlco'; did you mean 'xloc'?
cam a12, 1                          ; error: the camera table has no property 12
cam col, 1                          ; error: unknown camera property 'col'
cam 3, 1                            ; error: expected a camera property name, got '3'
er                                  ; => 0x00000000
er                                  ; => 0x00000000
