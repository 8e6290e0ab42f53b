// -W error: every warning becomes an error (and the run fails).
;! werror
cam xloc, 1e-8                       ; => 0x00000801 ; error: underflows to zero in float16 (smallest subnormal is 2^-24, about 5.96e-08) [-W error]
sp 0, col, a11, 1, 2                 ; => 0x00005ac5 0x00010002 ; error: prop and prop2 are both 'col'
er                                   ; => 0x00000000
er                                   ; => 0x00000000
