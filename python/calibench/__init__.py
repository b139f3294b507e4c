"""Calibench from Python: calibrate range sensors to cameras with printed boards.

Every function here runs the same work as the `calibench` command of the same name, in this
process (no executable is started): the same pipeline, the same files, the same messages. Options
are the command's flags with ``_`` for ``-`` (``huber_delta=0.05`` is ``--huber-delta 0.05``,
``no_jackknife=True`` is ``--no-jackknife``, ``pairs=["pose1", "pose2"]`` is
``--pairs pose1,pose2``); ``calibench help <command>`` and the man page list them.

    >>> import calibench
    >>> result = calibench.calibrate("my_capture/")          # a folder, a manifest or a recording
    >>> result.cam_from_lidar                                # 4x4 numpy array
    >>> result.std_t_m, result.std_r_deg                     # 1 sigma per camera axis
    >>> [p.id for p in result.pairs if p.status != "accepted"]
    >>> result.save("result.json")                           # calibench.result.v1

Errors raise :class:`Error` subclasses carrying the command's own message (the file named, what is
wrong). The core runs with the GIL released; what it prints is captured and returned (``log``)
instead of reaching the terminal, and ``progress(phase, done, total, item)`` is called as it goes.
"""

from __future__ import annotations

import json
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, Optional, Sequence, Union

import numpy as np

from . import _calibench

__all__ = [
    "AccuracyError", "Error", "InputError", "NoCalibrationError", "NotConstrainedError", "Pair",
    "Progress", "Result", "UsageError", "__version__", "advise", "calibrate", "check", "commands",
    "import_recording", "load_result", "lrf_calibrate", "report", "run",
]

__version__: str = _calibench.version

PathLike = Union[str, "os.PathLike[str]"]
Progress = Callable[[str, int, int, str], None]
"""progress(phase, done, total, item): phase is what is being done ("extracted" per pair,
"reading" per byte of a recording), item the pair's id ("" when counting bytes)."""


def _installed_assets() -> None:
    # An installed package lives in <prefix>/lib/python3/dist-packages/calibench; the assets in
    # <prefix>/share/calibench/assets. A build tree's module finds the source tree's by itself.
    if os.environ.get("CALIBENCH_ASSETS"):
        return
    assets = Path(__file__).resolve().parents[4] / "share" / "calibench" / "assets"
    if (assets / "report").is_dir():
        os.environ["CALIBENCH_ASSETS"] = str(assets)


_installed_assets()


# ---- errors: one class per exit code of the command line --------------------------------------


class Error(Exception):
    """A command failed. ``message`` is what the command line prints (the file and the problem);
    ``exit_code`` what it exits with; ``log`` everything it printed on stderr."""

    exit_code = -1

    def __init__(self, message: str, command: str = "", log: str = "",
                 result: Optional["Result"] = None):
        super().__init__(message)
        self.message = message
        self.command = command
        self.log = log
        self.result = result


class UsageError(Error, ValueError):
    """A bad option or value (exit code 1); the message names it, and suggests the near one."""

    exit_code = 1


class InputError(Error, OSError):
    """A file is missing, unreadable or malformed (exit code 2). When some pairs could not be read
    but the others gave a calibration, ``result`` holds it."""

    exit_code = 2


class NoCalibrationError(Error):
    """Too few usable pairs, or no initial guess (exit code 3)."""

    exit_code = 3


class NotConstrainedError(Error):
    """A result exists but the boards do not fix all six degrees of freedom (exit code 4): it is
    in ``result``, refused rather than called fine."""

    exit_code = 4


class AccuracyError(Error):
    """evaluate: the error is above the bounds given (exit code 5)."""

    exit_code = 5


_ERRORS = {e.exit_code: e for e in (UsageError, InputError, NoCalibrationError,
                                    NotConstrainedError, AccuracyError)}


# ---- running a command --------------------------------------------------------------------------


def _flag_args(options: Mapping[str, Any]) -> list[str]:
    """Keyword options as the command's flags: name_with_underscores -> --name-with-underscores.
    True adds the flag, False and None leave it out; a list gives its values after the flag, except
    for pairs (comma-separated, as the command line takes them)."""
    args: list[str] = []
    for name, value in options.items():
        flag = "--" + name.replace("_", "-")
        if value is None or value is False:
            continue
        if value is True:
            args.append(flag)
        elif isinstance(value, (list, tuple)):
            if name == "pairs":
                args.append(f"{flag}={','.join(str(v) for v in value)}")
            else:
                args += [flag, *[_text(v) for v in value]]
        else:
            args.append(f"{flag}={_text(value)}")
    return args


def _text(value: Any) -> str:
    # repr of a float is the shortest text that reads back as the same double.
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    return str(value)


@dataclass
class _Run:
    command: str
    exit_code: int
    out: str
    err: str


def run(*args: str, progress: Optional[Progress] = None) -> tuple[int, str, str]:
    """``calibench *args`` in this process: (exit code, stdout, stderr). No exception for a
    non-zero exit code; the functions below raise."""
    code, out, err = _calibench.run([os.fspath(a) for a in args], progress)
    return code, out.decode("utf-8", "replace"), err.decode("utf-8", "replace")


def commands() -> list[str]:
    """The command line's commands."""
    return list(_calibench.commands())


def _run(command: str, args: Sequence[str], progress: Optional[Progress]) -> _Run:
    code, out, err = run(command, *args, progress=progress)
    return _Run(command, code, out, err)


def _failure(run_: _Run, result: Optional["Result"] = None) -> Error:
    """The command's own words: its error lines ("calibench <command>: ..."), else its stderr's
    last lines."""
    lines = [line for line in run_.err.splitlines() if line.strip()]
    mine: list[str] = []
    follows = False  # an indented line goes on with the "calibench ...:" line above it
    for line in lines:
        if line.startswith("calibench"):
            mine.append(line)
            follows = True
        elif follows and line[:1].isspace():
            mine.append(line)
        else:
            follows = False
    message = "\n".join(mine or lines[-3:]) or f"calibench {run_.command} exited {run_.exit_code}"
    kind = _ERRORS.get(run_.exit_code, Error)
    return kind(message, run_.command, run_.err, result)


def _check(run_: _Run) -> _Run:
    if run_.exit_code != 0:
        raise _failure(run_)
    return run_


# ---- results --------------------------------------------------------------------------------


@dataclass(frozen=True)
class Pair:
    """One pair of a result: its verdict and what it contributed."""

    id: str
    status: str  # "accepted", or why not ("rejected", "failed", ...)
    reason: str  # why it is not used, or what was down-weighted ("" when nothing)
    weight: float  # the robust kernel's weight in the final iteration (0 = down-weighted to nothing)
    residuals: np.ndarray  # Ca2Lib Eq. (6) at the solution: the planes' normal difference [3]
    #                        (unitless, ~radians) and distance difference [m]; empty if not used
    document: Mapping[str, Any] = field(repr=False, compare=False)


class Result:
    """A calibration: the content of a calibench.result.v1 file, with numpy views of it.

    ``cam_from_lidar`` maps a point in the LiDAR's frame into the camera's (x right, y down, z
    forward); ``lidar_from_cam`` is its inverse. ``covariance`` is 6x6 over a right perturbation
    cam_from_lidar * Exp([rho (m); phi (rad)]); ``std_t_m`` and ``std_r_deg`` are 1 sigma per
    camera axis. For a 2D LRF result, ``cam_from_lidar`` is cam_from_lrf.
    """

    def __init__(self, text: str, summary: str = "", log: str = "", source: str = ""):
        self._text = text
        self.document: dict[str, Any] = json.loads(text)
        if self.document.get("format") != "calibench.result.v1":
            raise InputError(f"{source or 'result'}: not a calibench.result.v1 file "
                             f"(format {self.document.get('format')!r})")
        self.summary = summary
        """What the command line prints for this solve ("" for a loaded file)."""
        self.log = log
        """What the solve printed on stderr (progress, warnings)."""

    def _matrix(self, key: str) -> np.ndarray:
        for name in (key, key.replace("lidar", "lrf")):  # an LRF result: cam_from_lrf
            if name in self.document:
                m = np.array(self.document[name]["matrix"], dtype=float)
                m.setflags(write=False)
                return m
        raise KeyError(key)

    @property
    def cam_from_lidar(self) -> np.ndarray:
        """4x4: x_in_cam = cam_from_lidar @ x_in_lidar."""
        return self._matrix("cam_from_lidar")

    @property
    def lidar_from_cam(self) -> np.ndarray:
        """4x4, the inverse of cam_from_lidar."""
        return self._matrix("lidar_from_cam")

    @property
    def covariance(self) -> np.ndarray:
        """6x6 covariance of [rho (m); phi (rad)] (right perturbation of cam_from_lidar)."""
        return np.array(self.document["covariance_6x6"], dtype=float)

    @property
    def std_t_m(self) -> np.ndarray:
        """1 sigma of the translation along the camera's x, y, z [m]."""
        return np.array(self.document["std_translation_m"], dtype=float)

    @property
    def std_r_deg(self) -> np.ndarray:
        """1 sigma of the rotation about the camera's x, y, z [deg]."""
        return np.array(self.document["std_rotation_deg"], dtype=float)

    @property
    def well_constrained(self) -> bool:
        """Whether the boards fix all six degrees of freedom."""
        return bool(self.document.get("observability", {}).get("well_constrained", False))

    @property
    def pairs(self) -> list[Pair]:
        """Every pair of the dataset, used or not, in the file's order."""
        out = []
        for p in self.document.get("pairs", []):
            out.append(Pair(id=str(p.get("id", "")), status=str(p.get("status", "")),
                            reason=str(p.get("reason", "")),
                            weight=float(p.get("robust_weight", 1.0 if p.get("status") ==
                                               "accepted" else 0.0)),
                            residuals=np.array(p.get("residual", []), dtype=float), document=p))
        return out

    def save(self, path: PathLike) -> Path:
        """Writes the result file (exactly what the command line writes), atomically: a file of
        that name is replaced only once the new one is complete."""
        path = Path(path)
        tmp = tempfile.NamedTemporaryFile("w", dir=path.parent or ".", prefix=path.name + ".",
                                          suffix=".tmp", delete=False, encoding="utf-8")
        try:
            with tmp:
                tmp.write(self._text)
            os.replace(tmp.name, path)
        except BaseException:
            Path(tmp.name).unlink(missing_ok=True)
            raise
        return path

    def __repr__(self) -> str:
        t = self.cam_from_lidar[:3, 3]
        used = sum(p.status == "accepted" for p in self.pairs)
        return (f"<calibench.Result t=[{t[0]:.4f} {t[1]:.4f} {t[2]:.4f}] m, "
                f"sigma_t={np.round(self.std_t_m * 1e3, 2).tolist()} mm, "
                f"sigma_r={np.round(self.std_r_deg, 3).tolist()} deg, {used} pairs used>")


def load_result(path: PathLike) -> Result:
    """A calibench.result.v1 file (written by calibrate, lrf-calibrate or Result.save)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as e:
        raise InputError(f"{path}: cannot read: {e.strerror}") from e
    try:
        return Result(text, source=str(path))
    except json.JSONDecodeError as e:
        raise InputError(f"{path}: not JSON: {e}") from e


def _solve(command: str, args: list[str], out: Optional[PathLike],
           progress: Optional[Progress]) -> Result:
    """Runs a solving command writing its result to `out` (a temporary file when None) and reads
    it back. A result written despite a non-zero exit (not constrained, unreadable pairs) is
    attached to the error."""
    with tempfile.TemporaryDirectory(prefix="calibench-") as tmp:
        path = Path(out) if out is not None else Path(tmp) / "result.json"
        run_ = _run(command, args + ["--out", os.fspath(path)], progress)
        result = None
        if path.is_file() and run_.exit_code in (0, 2, 4):
            wrote = f"wrote {path}\n"
            summary = run_.out.replace(wrote, "") if out is None else run_.out
            result = Result(path.read_text(encoding="utf-8"), summary, run_.err, str(path))
        if run_.exit_code != 0 or result is None:
            raise _failure(run_, result)
        return result


# ---- the commands ------------------------------------------------------------------------------


def calibrate(dataset: Optional[PathLike] = None, method: Optional[str] = None, *,
              session: Optional[PathLike] = None, out: Optional[PathLike] = None,
              report: Optional[PathLike] = None, progress: Optional[Progress] = None,
              **options: Any) -> Result:
    """`calibench calibrate`: a LiDAR to a camera from board planes.

    dataset: a folder (clouds/, images/, camera.yaml, target.json), a manifest, a recording, or a
    rig's camera with ``camera="cam0"``; or give ``session`` (a workbench session: its brushes,
    rejections and solver choices). A 2D LRF dataset or session runs the LRF method's job, as
    ``lrf_calibrate`` does. method: weighted-ml (the default) | ca2lib-gn | kim. out: also write the
    result file there; report: the HTML report. Other options: the command's flags
    (``huber_delta``, ``pairs``, ``initial_guess``, ``no_jackknife``, ``estimate_range_offset``,
    ``estimate_intrinsics``, ``lidar_model``, ``threads``, ...).

    Raises NotConstrainedError (with ``.result``) when the boards leave a direction free,
    NoCalibrationError when too few pairs are usable, InputError for unreadable files.
    """
    args = [] if method is None else ["--method", method]
    if dataset is not None:
        args += ["--dataset", os.fspath(dataset)]
    if session is not None:
        args += ["--session", os.fspath(session)]
    if report is not None:
        args += ["--report", os.fspath(report)]
    return _solve("calibrate", args + _flag_args(options), out, progress)


def lrf_calibrate(dataset: Optional[PathLike] = None, method: Optional[str] = None, *,
                  session: Optional[PathLike] = None, out: Optional[PathLike] = None,
                  progress: Optional[Progress] = None, **options: Any) -> Result:
    """`calibench lrf-calibrate`: a 2D laser rangefinder to a depth camera (three-face target) or
    an RGB camera (checkerboard). method: refined (the default) | paper-linear; or give
    ``session`` (the LRF workbench's calibench.lrf-session.json: its rejections and method, and its
    dataset unless ``dataset`` is given). Options: ``error_threshold``, ``huber_delta``, ``pairs``,
    ``threads``. The result's ``cam_from_lidar`` is cam_from_lrf."""
    args = []
    if dataset is not None:
        args += ["--dataset", os.fspath(dataset)]
    if session is not None:
        args += ["--session", os.fspath(session)]
    if method is not None:
        args += ["--method", method]
    return _solve("lrf-calibrate", args + _flag_args(options), out, progress)


def advise(dataset: PathLike, *, progress: Optional[Progress] = None,
           **options: Any) -> dict[str, Any]:
    """`calibench advise --json`: is the capture enough for the goal (``goal_mm``, ``goal_deg``),
    and where to hold the board next. Returns the documented JSON object (``done``, ``sigma``,
    ``next``, ...)."""
    run_ = _check(_run("advise", ["--dataset", os.fspath(dataset), "--json"] +
                       _flag_args(options), progress))
    return json.loads(run_.out)


def check(dataset: PathLike, result: Union[Result, PathLike], *,
          write_result: Optional[PathLike] = None, progress: Optional[Progress] = None,
          **options: Any) -> dict[str, Any]:
    """`calibench check --json`: is a calibration still right, judged from the scene without a
    target. ``dataset`` is a folder, manifest or recording; ``result`` a Result or its file.
    Options as the command's (``search_deg``, ``search_m``, ``tolerance_deg``, ``tolerance_m``,
    ``max_frames``, ...). Returns the documented object: ``verdict`` ("consistent",
    "miscalibrated" or "cannot tell"), ``why``, ``frames_used``, ``cam_from_lidar`` (4x4 numpy,
    None without an estimate), ``sigma_t_mm``, ``sigma_r_deg``, ``change_t_mm``,
    ``change_r_deg``, ``unconstrained_axes``. ``write_result`` saves the estimate as a result file
    (its provenance says targetless); load it with load_result."""
    with tempfile.TemporaryDirectory(prefix="calibench-") as tmp:
        if isinstance(result, Result):
            result = result.save(Path(tmp) / "result.json")
        args = ["--dataset", os.fspath(dataset), "--result", os.fspath(result), "--json"]
        if write_result is not None:
            args += ["--write-result", os.fspath(write_result)]
        run_ = _check(_run("check", args + _flag_args(options), progress))
    out = json.loads(run_.out)
    for key in ("cam_from_lidar", "reference_cam_from_lidar"):
        if out.get(key) is not None:
            out[key] = np.array(out[key], dtype=float)
    return out


def report(out: PathLike, result: Union[Result, PathLike], *, dataset: Optional[PathLike] = None,
           session: Optional[PathLike] = None, views: bool = True,
           progress: Optional[Progress] = None, **options: Any) -> Path:
    """`calibench report`: the self-contained HTML report of a result (a Result or its file, of
    either method: LiDAR-camera or 2D LRF) on its dataset (or session). views=False leaves out the rendered views (no OpenGL needed);
    ``no_cross_validation=True`` skips the leave-one-out re-solves. Returns the report's path."""
    with tempfile.TemporaryDirectory(prefix="calibench-") as tmp:
        if isinstance(result, Result):
            result = result.save(Path(tmp) / "result.json")
        args = ["--out", os.fspath(out), "--result", os.fspath(result)]
        if dataset is not None:
            args += ["--dataset", os.fspath(dataset)]
        if session is not None:
            args += ["--session", os.fspath(session)]
        if not views:
            args.append("--no-views")
        _check(_run("report", args + _flag_args(options), progress))
    return Path(out)


def import_recording(recording: PathLike, out: Optional[PathLike] = None, *,
                     board: Optional[str] = None, progress: Optional[Progress] = None,
                     **options: Any) -> dict[str, Any]:
    """`calibench import`: a ROS 1 .bag, ROS 2 .db3 / .mcap recording into a dataset folder (one
    pair per still hold of the board). board: a preset (a3, a4, charuco-a3, charuco-a4) or a
    target.json. Options: ``cloud_topic``, ``image_topic``, ``camera_info_topic``, ``camera``,
    ``max_offset``, ``still_window``, ``max_pairs``, ``calibrate``, ... Returns the folder's
    import.json (what was written, what was dropped and why) with ``folder`` added."""
    args = [os.fspath(recording)]
    if out is not None:
        args += ["--out", os.fspath(out)]
    if board is not None:
        args += ["--board", os.fspath(board)]
    run_ = _check(_run("import", args + _flag_args(options), progress))
    manifest = next((line.split(":", 1)[1].strip() for line in run_.out.splitlines()
                     if line.startswith("dataset:")), None)
    folder = Path(manifest).parent if manifest else Path(out) if out is not None else None
    if folder is None or not (folder / "import.json").is_file():
        return {"folder": str(folder) if folder else None, "log": run_.out}
    record = json.loads((folder / "import.json").read_text(encoding="utf-8"))
    record["folder"] = str(folder)
    return record
