"""The two helpers of pythonocc's `OCC.Extend` that BladeX imports."""
