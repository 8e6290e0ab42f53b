; animation.asm: a looping animation over eight frames.
;
; Shows:  nf renders a frame and lets the program continue; lr jumps back so the
;         animation loops. A green sphere orbits a fixed red one in eight steps of 45
;         degrees in the x-z plane (positions written out below); the red sphere's shadow
;         does not change, but the green sphere passes in front of and behind it.
; Run:    rend3r emulate programs/animation.asm --frames 8 -o 'out/anim_{n:03}.png'
;         (or --gif out/anim.gif)
; Look:   frame 0: the small green sphere to the right of the red one; frame 2: in front
;         of it, larger, covering all but a thin red rim; frame 4: to the left; frame 6:
;         hidden behind it. In fp16 (the default) the green sphere's edge is ragged where
;         it is far and small (frames 0, 4, 5 and 7); --precision fp64 draws it smooth.
; frames: 8

R = 2.2                          ; orbit radius
D = 1.5556349                    ; R * sin 45

nr
cam rrot, 1
cam hfov, 0.25          ; field of view: 0.25 of the default 10 x 7.5 viewport
cam vfov, 0.25
lt 0, src, 1
lt 0, xfor, -0.5
lt 0, yfor, -1
lt 0, zfor, -1
lt 0, col, 0xFFFF
lt 0, int, 1

sp 0, type, col, 1, 0xF800       ; the red sphere in the middle
sp 0, xloc, yloc, 0, 0
sp 0, zloc, rrot, -6, 1
sp 0, xscl, yscl, 1, 1
sp 0, zscl, mat, 1, 0

sp 1, type, col, 1, 0x07E0       ; the green sphere, radius 0.6
sp 1, yloc, rrot, 0, 1
sp 1, xscl, yscl, 1 / 0.6, 1 / 0.6
sp 1, zscl, mat, 1 / 0.6, 0

sp 1, xloc, zloc, R, -6
nf
sp 1, xloc, zloc, D, -6 + D
nf
sp 1, xloc, zloc, 0, -6 + R
nf
sp 1, xloc, zloc, -D, -6 + D
nf
sp 1, xloc, zloc, -R, -6
nf
sp 1, xloc, zloc, -D, -6 - D
nf
sp 1, xloc, zloc, 0, -6 - R
nf
sp 1, xloc, zloc, D, -6 - D
nf
lr
er
er
