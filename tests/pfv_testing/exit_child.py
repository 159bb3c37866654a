"""A script that ends while O.run() runs with pfv engines, run by tests/yade/robustness/test_reset_cycles.py:

    yade-double -n -x tests/pfv_testing/exit_child.py ENGINES HOW

ENGINES pfv engines (lattice_scene.build_box, 300 spheres) run in the background; the script then ends as HOW says:
"end" (its last line), "pause" (O.pause() first: the run thread finishes its iteration after the script), "exit"
(sys.exit(0)). Prints "RUNNING <iterations>" before it ends; YADE's exit code must be 0.
"""
import sys
import time

from pfv_testing import lattice_scene
from yade import O

engines, how = int(sys.argv[1]), sys.argv[2]
lattice_scene.build_box(300, engines)
O.run()
while O.iter < 3:
    time.sleep(0.005)
print(f"RUNNING {O.iter}", flush=True)
if how == "pause":
    O.pause()
elif how == "exit":
    sys.exit(0)
