"""NeuFlow-V2 optical flow from Python: the C++ core, the flow formats and the pictures on NumPy arrays.

    import neuflow
    model = neuflow.Model("neuflow_mixed.pth")          # backend="auto": a GPU through Vulkan, else the CPU
    session = model.session(frame_order="bgr")          # frames as OpenCV reads them
    flow = session.compute(frame0, frame1)              # (H, W, 2) float32, u right and v down, in pixels
    neuflow.write_flow("out.flo", flow)
    picture = neuflow.flow_to_color(flow)               # (H, W, 3) uint8 RGB

help(neuflow.Model) and help(neuflow.Session) list the options.
"""

import numpy as _numpy

from . import _neuflow

if int(_numpy.__version__.split(".")[0]) >= 2 and _neuflow._pybind11_version < (2, 12):
    raise ImportError(f"neuflow was built with pybind11 {'.'.join(map(str, _neuflow._pybind11_version))}, which "
                      f"reads NumPy 1's arrays only, and this is NumPy {_numpy.__version__}: rebuild it with "
                      "pybind11 2.12 or later, or use NumPy 1")

from ._neuflow import (  # noqa: E402,F401
    BackendError,
    Model,
    ModelError,
    Session,
    __version__,
    _takes_without_copy,
    epe,
    flow_to_color,
    metrics,
    read_flow,
    write_flow,
)

__all__ = [
    "BackendError",
    "Model",
    "ModelError",
    "Session",
    "epe",
    "flow_to_color",
    "metrics",
    "read_flow",
    "write_flow",
]
