# Type stubs of the neuflow module (its compiled part, neuflow._neuflow, has no annotations).
import os
from typing import Literal, Optional, Tuple, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str

Path = Union[str, os.PathLike[str]]
Frame = npt.NDArray[np.uint8]  # (H, W, 3) in the session's frame_order, or (H, W) grey
Flow = npt.NDArray[np.float32]  # (H, W, 2): u (right), v (down) in pixels; NaN where invalid
FlowIn = npt.NDArray[np.floating]  # (H, W, 2), any float dtype (taken as float32)
Mask = npt.NDArray[Union[np.bool_, np.integer]]  # (H, W): nonzero where valid

class ModelError(Exception):
    """The file is not a NeuFlow-V2 checkpoint the core can load."""

class BackendError(RuntimeError):
    """The Vulkan backend cannot run: no device, out of memory, a lost device."""

class ModelInfo(TypedDict):
    architecture: str
    parameters: int
    checkpoint: str
    backend: str
    device: str
    precision: str
    threads: int
    warning: Optional[str]

class SessionOptions(TypedDict):
    iters_s16: int
    iters_s8: int
    model_size: Optional[Tuple[int, int]]
    channel_order: str
    frame_order: str

class Metrics(TypedDict):
    epe: float
    fl_all: float
    within_1px: float
    within_3px: float
    within_5px: float
    valid_pixels: int

class Session:
    """Computes flow with a Model; Model.session() makes one (there is no constructor)."""

    def compute(self, frame0: Frame, frame1: Frame) -> Flow:
        """The flow from frame0 to frame1 (same size). Does not touch the stream."""
    def push(self, frame: Frame) -> Optional[Flow]:
        """The flow from the previous frame to this one, or None for the first."""
    def reset(self) -> None:
        """Forgets the stream: the next push() returns None."""
    @property
    def device(self) -> str: ...
    @property
    def options(self) -> SessionOptions: ...
    def _time_compute(self, frame0: Frame, frame1: Frame, runs: int = 3) -> float: ...

class Model:
    """A NeuFlow-V2 checkpoint loaded for inference, shared read-only by its sessions."""

    def __init__(
        self,
        path: Path,
        backend: Literal["auto", "cpu", "vulkan"] = "auto",
        device: int = -1,
        precision: Literal["fp32", "fp16"] = "fp32",
        threads: int = 0,
        max_memory: int = 0,
    ) -> None: ...
    @property
    def info(self) -> ModelInfo: ...
    def session(
        self,
        iters_s16: int = 1,
        iters_s8: int = 8,
        model_size: Optional[Tuple[int, int]] = None,
        channel_order: Literal["rgb", "bgr"] = "rgb",
        frame_order: Optional[Literal["rgb", "bgr"]] = None,
    ) -> Session: ...

def read_flow(path: Path) -> Flow:
    """Reads a .flo, KITTI .png or .npy flow file; invalid pixels are NaN."""

def write_flow(path: Path, flow: FlowIn, valid: Optional[Mask] = None) -> None:
    """Writes a .flo, KITTI .png or .npy flow file, atomically."""

def flow_to_color(
    flow: FlowIn, max_flow: Optional[float] = None, valid: Optional[Mask] = None
) -> npt.NDArray[np.uint8]:
    """The colour-wheel picture of flow, (H, W, 3) RGB."""

def epe(flow: FlowIn, gt: FlowIn, valid: Optional[Mask] = None) -> float:
    """Mean end-point error in px over the pixels where gt is finite (and valid)."""

def metrics(flow: FlowIn, gt: FlowIn, valid: Optional[Mask] = None) -> Metrics:
    """epe, fl_all, within_1px/3px/5px and valid_pixels, as `neuflow eval` reports them."""

def _takes_without_copy(frame: Frame) -> bool: ...
