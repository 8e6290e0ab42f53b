// .isa_ext in an included file enables the extension for the rest of the program.
tr 0, x1, y1, 1, 2                   ; => 0x00000885 0x3c004000
.include "hybrid.inc"
ts triangle                          ; => 0x00000012
tr 0, x1, y1, 1, 2                   ; => 0x00000885 0x3c004000
er                                   ; => 0x00000000
er                                   ; => 0x00000000
