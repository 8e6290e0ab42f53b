"""Getting programs onto a REND3R device: the load protocol, its links and a virtual device."""
