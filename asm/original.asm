// The original device's assembler, line for line: what it accepted assembles to the same
// words here (docs/assembly.md, "Differences from the original assembler"); a warning
// where the source likely meant something else. Values go to camera xloc (prop 1):
// word = bits << 16 | 0x0801.
// A 0x or 0b literal for a float16 property is a 16-bit integer read as signed.
cam xloc, 0x3c00                     ; => 0x73800801 ; warning: 0x3c00 is the integer 15360
cam xloc, 0x7fff                     ; => 0x78000801 ; warning: 0x7fff is the integer 32767
cam xloc, 0x8000                     ; => 0xf8000801 ; warning: signed 16-bit integer -32768
cam xloc, 0xbc00                     ; => 0xf4400801 ; warning: signed 16-bit integer -17408
cam xloc, 0xFFFF                     ; => 0xbc000801 ; warning: signed 16-bit integer -1
cam xloc, 0XFF_FF                    ; => 0xbc000801 ; warning: write 0hffff for raw bits
cam xloc, 0b1000000000000001         ; => 0xf8000801 ; warning: signed 16-bit integer -32767
cam xloc, 0b0111_1111_1111_1111      ; => 0x78000801
cam xloc, (0xbc00)                   ; => 0xf4400801 ; warning: signed 16-bit integer -17408
lt 0, xfor, 0xbc00                   ; => 0xf4402003 ; warning: signed 16-bit integer -17408
sp 0, xloc, yloc, 0xbc00, 0xffff     ; => 0x00000885 0xf440bc00 ; warning: -17408 ; warning: -1
cam xloc, 0hbc00                     ; => 0xbc000801
lt 0, col, 0xbc00                    ; => 0xbc003803
// Magnitudes of 65520 and above round to infinity.
cam xloc, 1e5                        ; => 0x7c000801 ; warning: 1e5 overflows float16 to infinity
cam xloc, -1e5                       ; => 0xfc000801 ; warning: overflows float16 to -infinity
cam xloc, 65535.9                    ; => 0x7c000801 ; warning: overflows float16 to infinity
cam xloc, 0x10000                    ; => 0x7c000801 ; warning: overflows float16 to infinity
cam xloc, 65519.99                   ; => 0x7bff0801
// inf, infinity and nan in any case, signed; they take no other arithmetic.
cam xloc, inf                        ; => 0x7c000801
cam xloc, -inf                       ; => 0xfc000801
cam xloc, +Infinity                  ; => 0x7c000801
cam xloc, INF                        ; => 0x7c000801
cam xloc, nan                        ; => 0x7e000801
cam xloc, -NaN                       ; => 0xfe000801
cam xloc, -(-inf)                    ; => 0x7c000801
cam xloc, inf + 1                    ; error: inf and nan cannot be used in arithmetic
cam xloc, 2 * nan                    ; error: inf and nan cannot be used in arithmetic
lt 0, col, inf                       ; error: 'col' takes an integer or 0h raw bits, got inf
lt inf, xloc, 1                      ; error: light index must be an integer
cam xloc, infinite                   ; error: undefined name 'infinite'
nan = 2                              // a constant may take the name; it then wins
cam xloc, nan                        ; => 0x40000801
// Triangle property 10 is named none (the device ignores it).
tr 3, none, x1, 1, 2                 ; => 0x0000505d 0x3c004000
tr 524287, x3, NONE, -1, 0xbc00      ; => 0xffff3abd 0xbc00f440 ; warning: signed 16-bit integer -17408
tr 3, none, none, 1, 2               ; => 0x0000529d 0x3c004000 ; warning: both 'none'
sp 3, none, xloc, 1, 2               ; error: unknown shape property 'none'
cam none, 1                          ; error: unknown camera property 'none'
er                                   ; => 0x00000000
er                                   ; => 0x00000000
