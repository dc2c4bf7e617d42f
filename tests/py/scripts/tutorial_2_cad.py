# PyGeM's tutorial 2 (tutorials/tutorial2/tutorial-2-iges.py, "Free Form Deformation on a
# cylinder in CAD file format") as a script for cadmorph: PyGeM's code, line for line,
# with the one changed import (marked); the file names come from the command line.
# Usage: tutorial_2_cad.py PRM INPUT.igs|stp OUTPUT.igs|stp
import sys

from cadmorph.pygem.cad import FFD  # PyGeM: from pygem.cad import FFD

ffd = FFD()
ffd.read_parameters(sys.argv[1])
print(ffd)

input_cad_file_name = sys.argv[2]
modified_cad_file_name = sys.argv[3]
ffd(input_cad_file_name, modified_cad_file_name)

with open(input_cad_file_name, encoding="utf-8") as f1, open(modified_cad_file_name, encoding="utf-8") as f2:
    lines1 = f1.readlines()
    lines2 = f2.readlines()

# Determine max width for alignment
max_len = max(len(line.rstrip()) for line in lines1)

for l1, l2 in zip(lines1, lines2):
    l1_clean = l1.rstrip()
    l2_clean = l2.rstrip()
    sep = " | " if l1_clean != l2_clean else "   "
    print(f"{l1_clean.ljust(max_len)}{sep}{l2_clean}")

# Handle extra lines if files have different lengths
if len(lines1) > len(lines2):
    for l1 in lines1[len(lines2):]:
        print(f"{l1.rstrip().ljust(max_len)} | ")
elif len(lines2) > len(lines1):
    for l2 in lines2[len(lines1):]:
        print(f"{' '.ljust(max_len)} | {l2.rstrip()}")
