; lights.asm: several coloured lights of both kinds.
;
; Shows:  four lights summed on white shapes: a red directional light from the left, a
;         blue directional light from the right, a green point light above and in front
;         of the spheres at half intensity, and light 3 switched off (src 0) with full
;         white intensity to show that an off light adds nothing.
; Run:    rend3r emulate programs/lights.asm -o out/lights.png
; Look:   three white spheres in a row, each red on its left and blue on its right,
;         purple between; the green point light tints their tops (teal over blue, yellow
;         over red). The middle sphere shades its neighbours' inner flanks from the side
;         lights: the left sphere's right edge and the right sphere's left edge lie beyond
;         a straight vertical shadow line, lit dark green by the point light alone.
; frames: 1

nr
cam rrot, 1
cam hfov, 0.25          ; field of view: 0.25 of the default 10 x 7.5 viewport
cam vfov, 0.25

lt 0, src, 1                    ; red, directional, travelling right
lt 0, xfor, 1
lt 0, yfor, 0
lt 0, zfor, -0.5
lt 0, col, 0b11111_000000_00000
lt 0, int, 1

lt 1, src, 1                    ; blue, directional, travelling left
lt 1, xfor, -1
lt 1, yfor, 0
lt 1, zfor, -0.5
lt 1, col, 0b00000_000000_11111
lt 1, int, 1

lt 2, src, 2                    ; green point light above the middle sphere
lt 2, xloc, 0
lt 2, yloc, 3
lt 2, zloc, -3
lt 2, col, 0b00000_111111_00000
lt 2, int, 0.5

lt 3, src, 0                    ; off: must not contribute
lt 3, xfor, 0
lt 3, yfor, 0
lt 3, zfor, -1
lt 3, col, 0xFFFF
lt 3, int, 1

.rept 3, i
sp i, type, col, 1, 0xFFFF
sp i, xloc, yloc, (i - 1) * 2.4, 0
sp i, zloc, rrot, -5, 1
sp i, xscl, yscl, 1, 1
sp i, zscl, mat, 1, 0
.endr

nf
er
er
