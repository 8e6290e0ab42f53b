// Malformed lines: each gets one clear error, and the lines after it still assemble.
cam xloc 1                           ; error: unexpected '1', expected
cam @, 1                             ; error: unexpected character '@'
cam xloc, ½                          ; error: unexpected character '½'
cam xloc,                            ; error: unexpected end of line, expected
cam xloc, (1 + 2                     ; error: unexpected end of line, expected ')'
cam xloc, 1)                         ; error: unexpected ')'
X =                                  ; error: unexpected end of line
3 = 4                                ; error: unexpected '3', expected a directive or a name
cam "x", 1                           ; error: unexpected '"x"'
.include "a.asm                      ; error: unexpected character
foo 1                                ; error: unknown mnemonic 'foo'
spp 0, xloc, yloc, 1, 2              ; error: unknown mnemonic 'spp'; did you mean 'sp'?
sp 0, xloc, yloc, 1                  ; error: 'sp' takes 5 operands (INDEX, PROP, PROP2, VALUE, VALUE2), got 4
tr 0                                 ; error: 'tr' takes 5 operands
cam                                  ; error: 'cam' takes 2 operands (PROP, VALUE), got 0
lt 0, xloc, 1, 2                     ; error: 'lt' takes 3 operands (INDEX, PROP, VALUE), got 4
cam -xloc, 1                         ; error: expected a camera property name, got '-xloc'
sp 0, xloc, 1, 1, 1                  ; error: expected a shape property name, got '1'
sp 0, bogus, yloc, 1 / 0, 1          ; error: unknown shape property 'bogus' ; error: division by zero
cam xloc, 1.5                        ; => 0x3e000801
er                                   ; => 0x00000000
er                                   ; => 0x00000000
