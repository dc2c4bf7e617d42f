"""pythonocc's viewer package: BladeX imports it at module level; the benchmark never
opens a window."""
