"""``rend3r explore``: which uniform number format each scene needs, and what it costs.

:mod:`.campaign` holds the tasks (program words and options in, plain results out),
:mod:`.report` the CSV, SVG and Markdown outputs, :mod:`.cli` the command.
"""
