// Without the hybrid extension, ts is an unknown mnemonic (with how to enable it) and
// a TS word can only be written as .word; ts is then free as a constant name.
ts shape                             ; error: unknown mnemonic 'ts': it belongs to the hybrid ISA extension
TS triangle                          ; error: enable it with '.isa_ext hybrid' in the source (or --isa-ext hybrid)
.word 0x0000000a                     ; => 0x0000000a
.word 0x00000012                     ; => 0x00000012
ts = 3
cam xloc, ts                         ; => 0x42000801
tr 0, x1, y1, 1, 2                   ; => 0x00000885 0x3c004000
er                                   ; => 0x00000000
er                                   ; => 0x00000000
