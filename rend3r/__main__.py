"""``python -m rend3r``: the command line (Ctrl-C while it loads exits 130, as in a command)."""

try:
    from .cli import main
except KeyboardInterrupt:
    import sys

    print("\nrend3r: interrupted", file=sys.stderr)
    sys.exit(130)

main()
