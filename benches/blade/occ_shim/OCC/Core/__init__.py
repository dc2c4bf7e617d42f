"""`OCC.Core.<Module>` -> `OCP.<Module>`, plus pythonocc's lower-case static holders
(`topods`, `brepbndlib`, ...) whose methods OCP names with an `_s` suffix."""
import importlib
import importlib.abc
import importlib.util
import sys


class _Statics:
    """`topods.Shell(x)` -> `TopoDS.Shell_s(x)`."""

    def __init__(self, cls):
        self._cls = cls

    def __getattr__(self, name):
        try:
            return getattr(self._cls, name + "_s")
        except AttributeError:
            return getattr(self._cls, name)


class _Loader(importlib.abc.Loader):
    def __init__(self, target):
        self.target = target

    def create_module(self, spec):
        return importlib.import_module(self.target)

    def exec_module(self, module):
        short = self.target.split(".")[-1]
        cls = getattr(module, short, None)
        if cls is not None and not hasattr(module, short.lower()):
            setattr(module, short.lower(), _Statics(cls))


class _Finder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path, target=None):
        if fullname.startswith("OCC.Core."):
            target = "OCP." + fullname[len("OCC.Core."):]
            if importlib.util.find_spec(target) is None:
                return None
            return importlib.util.spec_from_loader(fullname, _Loader(target))
        return None


sys.meta_path.insert(0, _Finder())
