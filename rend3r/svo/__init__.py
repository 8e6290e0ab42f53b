"""Sparse voxel octrees after the SVO thesis: build, fixed-point traversal, cache and core
models, and hybrid frames (``rend3r svo``)."""
