"""``rend3r view``: a local web inspector of a program's frames, pixel histories and
diagnostics, re-rendered live as the source changes (``docs/view.md``)."""
