"""pythonocc's `OCC` package name, mapped onto OCP (cadquery's OpenCASCADE bindings)
so that BladeX, written for pythonocc, runs against the OCCT venv for the benchmark.
`OCC.Core.*` and the two STL helpers of `OCC.Extend.DataExchange` exist here;
`OCC.Display.SimpleGui.init_display` exists only to be imported (calling it raises)."""
