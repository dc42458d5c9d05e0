"""read_flow_ring.py on a Python without NumPy says so in one line (exit 1), instead of a traceback.

Usage: py_reader_without_numpy_test.py READ_FLOW_RING_PY
"""
import runpy
import sys

sys.modules["numpy"] = None  # what `import numpy` finds on a machine without it: an ImportError
reader = sys.argv[1]
sys.argv = [reader, "/neuflow-no-such-ring"]
try:
    runpy.run_path(reader, run_name="__main__")
except SystemExit as e:
    message = str(e.code)
    assert "needs NumPy" in message and "\n" not in message, message
    print("ok:", message)
    sys.exit(0)
sys.exit("read_flow_ring.py ran without NumPy")
