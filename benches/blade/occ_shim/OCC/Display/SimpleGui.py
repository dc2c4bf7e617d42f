"""`init_display` of pythonocc: imported by BladeX's shaft module, never called by the
benchmark; calling it says there is no viewer here."""


def init_display(*args, **kwargs):
    raise RuntimeError("no OCC viewer in the benchmark environment")
