"""NeuFlow-V2 optical flow from Python: the C++ core, the flow formats and the pictures on NumPy arrays.

    import neuflow
    model = neuflow.Model("neuflow_mixed.pth")          # backend="auto": a GPU through Vulkan, else the CPU
    session = model.session(frame_order="bgr")          # frames as OpenCV reads them
    flow = session.compute(frame0, frame1)              # (H, W, 2) float32, u right and v down, in pixels
    neuflow.write_flow("out.flo", flow)
    picture = neuflow.flow_to_color(flow)               # (H, W, 3) uint8 RGB

help(neuflow.Model) and help(neuflow.Session) list the options.
"""

from ._neuflow import (  # noqa: F401
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
