; hybrid.asm: a raytraced set for a hybrid frame with a sparse voxel octree.
;
; Shows:  the REND3R half of a hybrid frame (SVO thesis, Chapter 7.4): a wide, flat
;         grey ellipsoid as a floor, a blue sphere behind the middle and a red one in
;         front to the right, leaving a gap at (0, 0, -4) where `rend3r svo render
;         --with-program` places a voxel model. The merge keeps, per pixel, whichever of
;         the model and the program's shapes is nearer, so the model hides part of the
;         blue sphere behind it.
; Run:    rend3r emulate programs/hybrid.asm -o out/hybrid_set.png
;         rend3r svo model torus -o out/torus.ply
;         rend3r svo build out/torus.ply -o out/torus.svo --depth 7
;         rend3r svo render out/torus.svo --with-program programs/hybrid.asm --place 0,0,-4,1 -o out/hybrid.png
; Look:   alone: a grey floor curving away below a black sky, a blue sphere left of
;         centre and a smaller red one at the front right, each with its shadow on the
;         floor (in fp16 the red sphere's right edge is ragged); merged: the torus stands
;         in the middle, in front of the blue sphere.
; frames: 1

nr
cam rrot, 1
cam hfov, 0.25
cam vfov, 0.25
lt 0, src, 1
lt 0, xfor, -0.4
lt 0, yfor, -1
lt 0, zfor, -0.6
lt 0, col, 0xFFFF
lt 0, int, 1

sp 0, type, col, 1, 0b10000_100000_10000   ; floor: semi-axes 20 x 0.5 x 20
sp 0, xloc, yloc, 0, -1.6
sp 0, zloc, rrot, -6, 1
sp 0, xscl, yscl, 0.05, 2
sp 0, zscl, mat, 0.05, 0

sp 1, type, col, 1, 0b00100_011000_11111   ; blue sphere behind the gap
sp 1, xloc, yloc, -0.8, 0.6
sp 1, zloc, rrot, -7.5, 1
sp 1, xscl, yscl, 1 / 1.6, 1 / 1.6
sp 1, zscl, mat, 1 / 1.6, 0

sp 2, type, col, 1, 0b11111_001000_00100   ; red sphere in front, right
sp 2, xloc, yloc, 1.1, -0.5
sp 2, zloc, rrot, -3, 1
sp 2, xscl, yscl, 1 / 0.45, 1 / 0.45
sp 2, zscl, mat, 1 / 0.45, 0

nf
er
er
