#!/usr/bin/env python3
"""color_check.py - the colours OCCT's XCAF reader gives each placed part of a STEP file.

    tests/occt/.venv/bin/python tests/occt/color_check.py FILE

Reads FILE with STEPCAFControl_Reader (colours and names on) and walks the document's leaf
nodes (each placed part instance) with XCAFPrs_DocumentExplorer, the walk OCCT's own
exporters use. Prints JSON: {"file", "leaves": [{"path", "color", "faces", "styled"}]}
in walk order, where "color" is the leaf's surface colour (sRGB, 4 digits, or null),
"faces" its face count and "styled" the sorted surface colours of the sub-shapes styled
on their own (a face coloured apart from its part).
"""
import json
import os
import sys

from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPCAFControl import STEPCAFControl_Reader
from OCP.TCollection import TCollection_ExtendedString
from OCP.TDocStd import TDocStd_Document
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.XCAFPrs import XCAFPrs, XCAFPrs_DocumentExplorer, XCAFPrs_IndexedDataMapOfShapeStyle
from OCP.XCAFPrs import XCAFPrs_DocumentExplorerFlags_OnlyLeafNodes


def rgb(style):
    if not style.IsSetColorSurf():
        return None
    c = style.GetColorSurf()
    return [round(c.Red(), 4), round(c.Green(), 4), round(c.Blue(), 4)]


def main():
    path = sys.argv[1]
    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    r = STEPCAFControl_Reader()
    r.SetColorMode(True)
    r.SetNameMode(True)
    if r.ReadFile(path) != IFSelect_RetDone or not r.Transfer(doc):
        print(json.dumps({"file": os.path.basename(path), "error": "read failed"}))
        sys.exit(1)
    leaves = []
    ex = XCAFPrs_DocumentExplorer(doc, XCAFPrs_DocumentExplorerFlags_OnlyLeafNodes)
    while ex.More():
        node = ex.Current()
        styles = XCAFPrs_IndexedDataMapOfShapeStyle()
        XCAFPrs.CollectStyleSettings_s(node.Label, node.Location, styles)
        styled = sorted(c for c in (rgb(styles.FindFromIndex(i)) for i in range(1, styles.Extent() + 1)) if c)
        shape = XCAFPrs_DocumentExplorer.FindShapeFromPathId_s(doc, node.Id)
        n = 0
        fx = TopExp_Explorer(shape, TopAbs_FACE)
        while fx.More():
            n += 1
            fx.Next()
        leaves.append({"path": node.Id.ToCString(), "color": rgb(node.Style), "faces": n, "styled": styled})
        ex.Next()
    print(json.dumps({"file": os.path.basename(path), "leaves": leaves}))


if __name__ == "__main__":
    main()
