// .include (own directory, then -I directories), .rept (nested, with a variable), .word.
// The conformance test passes -I asm/include.
.include "consts.inc"
.include "include/consts.inc"        ; (same file by another path)
cam xloc, INC_SCALE * 4              ; => 0x3c000801
.include "bad.inc"
.include "cycle_a.inc"
.include "missing.inc"               ; error: cannot find include file 'missing.inc'
.include missing                     ; error: .include takes one quoted path
.rept 3, i
  lt i, xloc, i                      ; => 0x00000803 0x3c00080b 0x40000813
.endr
.rept 2, i
  .rept 2, j
    sp i * 2 + j, type, zero, 1, 0   ; => 0x00006805 0x00010000 0x0000680d 0x00010000 0x00006815 0x00010000 0x0000681d 0x00010000
  .endr
.endr
.REPT 2
  nr                                 ; => 0x00000200 0x00000200
.ENDR
.rept 0, k
  nr                                 ; a zero count runs the body never
.endr
.rept 2, i
  R = i * 0.5                        ; constants inside .rept are local to the iteration
  cam xloc, R                        ; => 0x00000801 0x38000801
.endr
.rept 2, i
  .rept 1, i                         ; error: 'i' is already defined
  .endr
.endr
.rept 2, i
  cam xloc, i / 0                    ; error: division by zero
.endr
.rept -1, i                          ; error: the .rept count -1 is out of range
.endr
.rept 1.5, i                         ; error: the .rept count must be an integer
.endr
.rept 2, er                          ; error: 'er' is a mnemonic and cannot name a .rept variable
.endr
.rept 2, 3                           ; error: a .rept variable must be a name
.endr
.rept                                ; error: .rept takes COUNT[, VAR]
.endr
.endr                                ; error: .endr without a .rept
.endr 3                              ; error: .endr takes no operands ; error: .endr without a .rept
.word 0xdeadbeef                     ; => 0xdeadbeef
.word 0, 1, 0xffffffff               ; => 0x00000000 0x00000001 0xffffffff
.WORD 2 * 3                          ; => 0x00000006
.word 0x1_0000_0000                  ; error: .word value 4294967296 is out of range
.word 0h12                           ; error: .word value must be an integer, not raw bits
.word "x"                            ; error: a string is not a number
.include "latin1.inc"                ; error: is not UTF-8 text (byte 0xe9 at offset 77)
.include "include"                   ; error: cannot find include file 'include'
.word                                ; error: .word takes one or more 32-bit values
.wrd 1                               ; error: unknown directive '.wrd'; did you mean '.word'?
er                                   ; => 0x00000000
er                                   ; => 0x00000000
.rept 2, i                           ; error: .rept without a matching .endr
