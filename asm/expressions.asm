// Named constants and exact arithmetic (+ - * / and parentheses, unary minus).
HALF = 0.5
TWO = 1 + 1
RED = 0b11111_000000_00000
cam xloc, HALF                       ; => 0x38000801
cam xloc, -HALF                      ; => 0xb8000801
cam xloc, TWO * HALF + 3             ; => 0x44000801
cam xloc, (TWO + 1) * -(HALF)        ; => 0xbe000801
cam xloc, 1 - 2 - 3                  ; => 0xc4000801
cam xloc, 12 / 4 / 3                 ; => 0x3c000801
cam xloc, 1 + 2 * 3                  ; => 0x47000801
cam xloc, +1                         ; => 0x3c000801
cam xloc, 65504 + 15.99 - 15.99      ; => 0x7bff0801
cam xloc, 65536 - 32                 ; => 0x7bff0801
lt 3, col, RED                       ; => 0xf800381b
lt TWO, xloc, 1                      ; => 0x3c000813
lt 0, col, RED / 2048                ; => 0x001f3803
RAWONE = 0h3c00
cam yloc, RAWONE                     ; => 0x3c001001
cam yloc, RAWONE * 2                 ; error: raw bits (0h...) cannot be used in arithmetic
cam xloc, 1 / 0                      ; error: division by zero
cam xloc, 1 / (HALF - 0.5)           ; error: division by zero
cam xloc, UNDEFINED                  ; error: undefined name 'UNDEFINED'
cam xloc, half                       ; error: undefined name 'half'; did you mean 'HALF'?
HALF = 2                             ; error: 'HALF' is already defined (at
sp = 1                               ; error: 'sp' is a mnemonic and cannot name a constant
CAM = 1                              ; error: 'CAM' is a mnemonic and cannot name a constant
BAD = 1 / 0                          ; error: division by zero
cam xloc, BAD                        ; a constant whose definition failed is not reported again
xloc = 2
cam xloc, xloc                       ; => 0x40000801
er                                   ; => 0x00000000
er                                   ; => 0x00000000
