; registers.asm: the sphere scene written with register aliases and odd spellings.
;
; Shows:  every property named by its register alias (a0..a13), the paper's "iro"
;         spelling, the zero property (index 0, ignored by the device), mixed-case
;         mnemonics, every material value (0..3; materials do not change the image), a
;         raw-bits value (0h3c00 = 1.0) and a named constant. It describes exactly the
;         scene of sphere.asm, so it must render to the same frame buffer.
; Run:    rend3r emulate programs/registers.asm -o out/registers.png
; Look:   identical to sphere.asm: a red disc lit from the upper right.
; frames: 1

ONE = 1

NR
cam a0, 0h1234                  ; zero property: any data, ignored
cam a4, ONE                     ; rrot
cam iro, 0                      ; the paper's spelling of irot
cam a10, 0.25                   ; hfov
cam A11, 0.25                   ; vfov (aliases are case-insensitive)

lt 0, a0, 1                     ; src
lt 0, a4, -1                    ; xfor
lt 0, a5, -1                    ; yfor
lt 0, a6, -1                    ; zfor
lt 0, a7, 0xFFFF                ; col
lt 0, a8, 0h3c00                ; int = 1.0 given as raw bits

Sp 0, a13, a11, 1, 0xF800       ; type, col
sp 0, a1, a2, 0, 0              ; xloc, yloc
sp 0, a3, a4, -3, 1             ; zloc, rrot
sp 0, iro, a6, 0, 0             ; irot, jrot
sp 0, a7, a8, 0, 1              ; krot, xscl
sp 0, a9, a10, 1, 1             ; yscl, zscl
sp 0, a0, a12, 0h0042, 3        ; zero, mat 3 (materials are not rendered)
sp 0, a12, a12, 2, 1            ; prop == prop2: the second write (mat 1) wins

; shapes 1..2: switched off (type 0) but fully described, with the other materials;
; they must not appear
sp 1, a13, a12, 0, 2
sp 1, a1, a3, 0, -2
sp 1, a4, a8, 1, 1
sp 1, a9, a10, 1, 1
sp 2, a13, a12, 0, 0
sp 2, a1, a3, 1, -2
sp 2, a4, a8, 1, 1
sp 2, a9, a10, 1, 1

nF
Er
eR
