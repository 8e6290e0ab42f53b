// The hybrid extension enabled by the caller (--isa-ext hybrid), not by the source.
;! isa-ext hybrid
ts triangle                          ; => 0x00000012
tr 0, x1, y1, 1, 2                   ; => 0x00000885 0x3c004000
sp 0, xloc, yloc, 1, 2               ; => 0x00000885 0x3c004000 ; warning: 'sp' writes the triangle table here
er                                   ; => 0x00000000
er                                   ; => 0x00000000
