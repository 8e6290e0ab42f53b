"""Golden images: image metrics, ``rend3r compare`` and ``rend3r render-all``."""
