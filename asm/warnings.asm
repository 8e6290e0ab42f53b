// Warnings: the program still assembles (exit 0) unless -W error is given.
sp 1, xloc, xloc, 1, 2               ; => 0x0000084d 0x3c004000 ; warning: prop and prop2 are both 'xloc'
sp 1, zero, zero, 0, 0               ; => 0x0000000d 0x00000000
tr 1, a12, mat, 1, 2                 ; => 0x0000630d 0x00010002 ; warning: prop and prop2 are both 'mat'
cam xloc, 0x3c00                     ; => 0x73800801 ; warning: 0x3c00 is the integer 15360 for float16 property 'xloc'; write 0h3c00 for raw bits
cam xloc, 0.0001                     ; => 0x068e0801
cam xloc, 1e-7                       ; => 0x00020801 ; warning: (19.2% off)
cam xloc, 1e-8                       ; => 0x00000801 ; warning: 1e-8 underflows to zero in float16
cam xloc, 1e-300                     ; => 0x00000801 ; warning: underflows to zero
er                                   ; => 0x00000000
nr                                   ; => 0x00000200 ; warning: program does not end with two 'er'
