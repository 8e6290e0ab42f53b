// TS table select, the hybrid ISA extension (docs/isa-extensions.md): enabled here by
// the source itself. TS: bits 31:5 zero, table 4:3 (01 shape, 10 triangle), opcode 010.
ts shape                             ; error: enable it with '.isa_ext hybrid'
.isa_ext hybrid
ts shape                             ; => 0x0000000a
ts triangle                          ; => 0x00000012
TS Shape  // case-insensitive        ; => 0x0000000a
	ts	TRIANGLE	; tabs             ; => 0x00000012
.ISA_EXT Hybrid                      ; enabling it again changes nothing
// sp and tr after the matching ts: no diagnostic
ts shape                             ; => 0x0000000a
sp 0, xloc, yloc, 1, 2               ; => 0x00000885 0x3c004000
sp 1, xloc, yloc, 1, 2               ; => 0x0000088d 0x3c004000
ts triangle                          ; => 0x00000012
tr 0, x1, y1, 1, 2                   ; => 0x00000885 0x3c004000
tr 1, X1, Y1, 1 / 2, 2 * 2           ; => 0x0000088d 0x38004400
// a pair whose mnemonic names the other table: one warning per ts
sp 0, xloc, yloc, 1, 2               ; => 0x00000885 0x3c004000 ; warning: 'sp' writes the triangle table here (the last 'ts' selected it)
sp 0, zloc, yloc, 1, 2               ; => 0x00001885 0x3c004000
ts shape                             ; => 0x0000000a
tr 0, x1, y1, 1 + 0, 2               ; => 0x00000885 0x3c004000 ; warning: put 'ts triangle' before it
.rept 2, i
  ts triangle                        ; => 0x00000012 0x00000012
  tr i, x1, y1, 1, 2                 ; => 0x00000885 0x3c004000 0x0000088d 0x3c004000
  ts shape                           ; => 0x0000000a 0x0000000a
  sp i, xloc, yloc, 1, 2             ; => 0x00000885 0x3c004000 0x0000088d 0x3c004000
.endr
// operand errors
ts                                   ; error: 'ts' takes one operand (shape or triangle), got 0
ts shape, triangle                   ; error: 'ts' takes one operand (shape or triangle), got 2
ts shapes                            ; error: 'ts' selects 'shape' or 'triangle', not 'shapes'; did you mean 'shape'?
ts 1                                 ; error: 'ts' selects 'shape' or 'triangle', not '1'
ts = 3                               ; error: 'ts' is a mnemonic and cannot name a constant
triangle = 3                         ; a constant may share a table's name
ts triangle                          ; => 0x00000012
tss shape                            ; error: unknown mnemonic 'tss'; did you mean 'ts'?
// the directive's own errors
.isa_ext                             ; error: .isa_ext takes an extension name: .isa_ext hybrid
.isa_ext hybird                      ; error: unknown ISA extension 'hybird'; did you mean 'hybrid'?
.isa_ext vector                      ; error: unknown ISA extension 'vector' (known: hybrid)
.isa_ext "hybrid"                    ; error: .isa_ext takes extension names, not '"hybrid"'
.isa_xt hybrid                       ; error: unknown directive '.isa_xt'; did you mean '.isa_ext'?
er                                   ; => 0x00000000
er                                   ; => 0x00000000
