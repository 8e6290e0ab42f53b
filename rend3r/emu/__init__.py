"""The REND3R emulator: instruction processor, float16 raytracer and rasterizer."""
