// float16 literals: extremes, subnormals, signed zero, rounding to nearest even.
// Every value goes to camera xloc (prop 1): word = bits << 16 | 0x0801.
cam xloc, 1                          ; => 0x3c000801
cam xloc, 65504                      ; => 0x7bff0801
cam xloc, 65519.99                   ; => 0x7bff0801
cam xloc, 65519.999999999            ; => 0x7bff0801
cam xloc, -65504                     ; => 0xfbff0801
cam xloc, 65520                      ; => 0x7c000801 ; warning: 65520 overflows float16 to infinity
cam xloc, -65520                     ; => 0xfc000801 ; warning: -65520 overflows float16 to -infinity
cam xloc, 1e999                      ; => 0x7c000801 ; warning: overflows float16 to infinity
cam xloc, 1e99999                    ; error: exponent of '1e99999' is out of range
cam xloc, 6.103515625e-5             ; => 0x04000801
cam xloc, 5.96e-8                    ; => 0x00010801
cam xloc, 5.9604644775390625e-8      ; => 0x00010801
cam xloc, 2.98023223876953125e-8     ; => 0x00000801 ; warning: underflows to zero
cam xloc, 1e-9                       ; => 0x00000801 ; warning: underflows to zero
cam xloc, -1e-9                      ; => 0x80000801 ; warning: underflows to zero
cam xloc, 2.9802322387695313e-8      ; => 0x00010801 ; warning: rounds to
cam xloc, 0                          ; => 0x00000801
cam xloc, -0                         ; => 0x80000801
cam xloc, -0.0                       ; => 0x80000801
cam xloc, -(0)                       ; => 0x80000801
cam xloc, -(-0)                      ; => 0x00000801
cam xloc, 0 * -1                     ; => 0x80000801
cam xloc, -0 + 0                     ; => 0x00000801
cam xloc, -0 + -0                    ; => 0x80000801
cam xloc, -0 - 0                     ; => 0x80000801
cam xloc, 1 - 1                      ; => 0x00000801
cam xloc, 0 / -5                     ; => 0x80000801
cam xloc, 0.1                        ; => 0x2e660801
cam xloc, 0.2                        ; => 0x32660801
cam xloc, 1 / 3                      ; => 0x35550801
cam xloc, 0.1 * 3                    ; => 0x34cd0801
cam xloc, 2049                       ; => 0x68000801
cam xloc, 2051                       ; => 0x68020801
cam xloc, 2049.0000001               ; => 0x68010801
cam xloc, 1.00048828125              ; => 0x3c000801
cam xloc, 1.00146484375              ; => 0x3c020801
cam xloc, 1.000488281250000000000001 ; => 0x3c010801
cam xloc, 4098                       ; => 0x6c000801
cam xloc, 4102                       ; => 0x6c020801
cam xloc, 1e-5                       ; => 0x00a80801
cam xloc, 1e-6                       ; => 0x00110801 ; warning: rounds to
cam xloc, 1_000.5                    ; => 0x63d10801
cam xloc, 1.5e3                      ; => 0x65dc0801
cam xloc, 1.5E+3                     ; => 0x65dc0801
cam xloc, 15e-1                      ; => 0x3e000801
cam xloc, 1.                         ; => 0x3c000801
cam xloc, .5                         ; => 0x38000801
cam xloc, 0b11                       ; => 0x42000801
cam xloc, 0x3c00                     ; => 0x73800801 ; warning: write 0h3c00 for raw bits
cam xloc, 0h3c00                     ; => 0x3c000801
cam xloc, 0h7c00                     ; => 0x7c000801
cam xloc, 0h7e00                     ; => 0x7e000801
cam xloc, 0hFFFF                     ; => 0xffff0801
cam xloc, 0h1                        ; => 0x00010801
cam xloc, 0h12345                    ; error: raw bits '0h12345' have more than 4 hex digits
cam xloc, 0h                         ; error: malformed raw-bits number '0h'
cam xloc, 0hxyz                      ; error: malformed raw-bits number '0hxyz'
cam xloc, -0h3c00                    ; error: raw bits (0h...) cannot be used in arithmetic
cam xloc, 0h3c00 + 1                 ; error: raw bits (0h...) cannot be used in arithmetic
cam xloc, 1__0                       ; error: malformed number '1__0'
cam xloc, 1e                         ; error: malformed number '1e'
cam xloc, 1.2.3                      ; error: malformed number '1.2.3'
cam xloc, 12abc                      ; error: malformed number '12abc'
cam xloc, 1_                         ; error: malformed number '1_'
er                                   ; => 0x00000000
er                                   ; => 0x00000000
