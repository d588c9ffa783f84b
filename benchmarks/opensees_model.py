"""The same scene in OpenSeesPy, as a structural engineer would build it.

One-dimensional model (``-ndm 1 -ndf 1``), displacements relative to the
ground (uniform support excitation):

* a node per floor and per sliding base, with its lumped mass;
* each storey a ``zeroLength`` element of ``uniaxialMaterial Elastic E=k eta=c``;
  a yielding storey (``yield_force``) a ``Steel01`` element (F_y, E0 = k, b =
  ``hardening``: bilinear with kinematic hardening, the same law) beside an
  ``Elastic E=0 eta=c`` dashpot;
* each sliding base tied to the ground by a ``zeroLength`` element of
  ``ElasticPP`` with yield force μW and yield displacement 1e-5 m (a
  regularised Coulomb friction; a fixed base is a fixed floor-0 node);
* each contact a ``zeroLength`` element of ``ViscoelasticGap`` (K = k_imp,
  C = c_imp, gap −d) between the two floors: the tensile Kelvin–Voigt element
  of the study, closed while the penetration is positive;
* Newmark average acceleration (γ = 1/2, β = 1/4) at a fixed step, Newton
  iterations (with a line search when storeys yield), the record as a ``Path`` time series (linear interpolation).

OpenSeesPy is optional (``pip install openseespy``, or the ``bench`` extra).
Its Linux wheel for Python 3.11 (openseespylinux 3.7.1.2) ships its BLAS,
LAPACK and gfortran libraries in a ``lib`` folder that the dynamic loader
does not search; :func:`load_opensees` preloads them.
"""

from __future__ import annotations

import ctypes
import importlib.util
import tempfile
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import numpy as np

from benchmarks.outcome import Outcome
from stochpound.motions.ground import SampledMotion
from stochpound.model.scene import Scene

FRICTION_YIELD_DISPLACEMENT = 1e-5
"""Yield displacement of the ElasticPP friction element, m."""
YIELDING_TOLERANCE = 1e-9
"""Newton's displacement-increment tolerance in a model with yielding storeys, m (1e-12 m in an elastic one)."""
_BUNDLED_LIBRARIES = ("libquadmath.so.0", "libgfortran.so.4", "libblas.so.3", "liblapack.so.3", "libgomp.so.1")
_GROUND = 1


class OpenSeesUnavailable(RuntimeError):
    """OpenSeesPy is not installed or cannot be loaded."""


def load_opensees() -> ModuleType:
    """Import ``openseespy.opensees``, preloading the libraries its Linux wheel bundles.

    Raises
    ------
    OpenSeesUnavailable
        When OpenSeesPy is not installed or fails to load.
    """
    spec = importlib.util.find_spec("openseespylinux")
    if spec is not None and spec.origin:
        bundled = Path(spec.origin).parent / "lib"
        for name in _BUNDLED_LIBRARIES:
            if (bundled / name).exists():
                ctypes.CDLL(str(bundled / name), mode=ctypes.RTLD_GLOBAL)
    try:
        import openseespy.opensees as ops
    except Exception as error:  # the package raises RuntimeError, or ImportError when absent
        raise OpenSeesUnavailable(f"openseespy cannot be imported: {error}") from None
    return ops


def opensees_version() -> str:
    """Installed OpenSeesPy version, or ``"not installed"``."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("openseespy")
    except PackageNotFoundError:
        return "not installed"


@dataclass(frozen=True)
class _Layout:
    """Node tags of the model: per building, its base node (ground if fixed) and floor nodes."""

    base_nodes: list[int]
    floor_nodes: list[list[int]]
    contact_elements: list[int]


class OpenSeesModel:
    """One scene as an OpenSeesPy model, analysed at a fixed time step.

    Parameters
    ----------
    scene : Scene
        Tensile contacts with positive gaps, μ_s = μ, sampled ground motion.
    dt : float
        Newmark time step, s; the motion's sample spacing must be a whole multiple of it.
    """

    def __init__(self, scene: Scene, dt: float) -> None:
        _check_supported(scene)
        per_sample = scene.motion.dt / dt
        if abs(per_sample - round(per_sample)) > 1e-9:
            raise ValueError(f"dt must divide the motion's sample spacing {scene.motion.dt:g} s, got {dt:g}")
        self.scene, self.dt, self.steps_per_sample = scene, dt, int(round(per_sample))
        self.ops = load_opensees()

    def run(self) -> Outcome:
        """Build the model, analyse the whole motion and return the benchmark outcome."""
        ops = self.ops
        with tempfile.TemporaryDirectory(prefix="stochpound-opensees-") as folder:
            ops.wipe()
            ops.logFile(str(Path(folder) / "opensees.log"), "-noEcho")
            layout = self._build()
            files = self._recorders(layout, Path(folder))
            self._analyse()
            ops.wipe()  # flushes and closes the recorders
            return self._outcome(layout, files)

    # ------------------------------------------------------------- model

    def _build(self) -> _Layout:
        ops, scene = self.ops, self.scene
        ops.model("basic", "-ndm", 1, "-ndf", 1)
        ops.node(_GROUND, 0.0)
        ops.fix(_GROUND, 1)
        tags = _TagCounter(start=_GROUND + 1)
        base_nodes, floor_nodes = [], []
        for building in scene.buildings:
            below = base = self._base(building, tags)
            floors = []
            yield_forces = building.yield_force if building.yield_force is not None else (None,) * len(building.mass)
            for mass, stiffness, damping, yield_force in zip(building.mass, building.stiffness, building.damping, yield_forces):
                node = tags.next()
                ops.node(node, 0.0)
                ops.mass(node, mass)
                if yield_force is None:
                    self._link(below, node, tags, "Elastic", stiffness, damping)
                else:
                    self._link(below, node, tags, "Steel01", yield_force, stiffness, building.hardening)
                    self._link(below, node, tags, "Elastic", 0.0, damping)
                floors.append(node)
                below = node
            base_nodes.append(base)
            floor_nodes.append(floors)
        contacts = [self._contact(contact, floor_nodes, tags) for contact in scene.contacts]
        return _Layout(base_nodes, floor_nodes, contacts)

    def _base(self, building, tags: _TagCounter) -> int:
        """The node under floor 1: the ground for a fixed base, else a sliding base node."""
        if building.base is None:
            return _GROUND
        ops, node = self.ops, tags.next()
        ops.node(node, 0.0)
        ops.mass(node, building.base.mass)
        yield_force = building.base.mu * self.scene.g * building.total_mass
        self._link(_GROUND, node, tags, "ElasticPP", yield_force / FRICTION_YIELD_DISPLACEMENT, FRICTION_YIELD_DISPLACEMENT)
        if building.base.restoring_stiffness > 0.0:
            self._link(_GROUND, node, tags, "Elastic", building.base.restoring_stiffness)
        return node

    def _contact(self, contact, floor_nodes: list[list[int]], tags: _TagCounter) -> int:
        left = floor_nodes[contact.left][contact.left_floor - 1]
        right = floor_nodes[contact.right][contact.right_floor - 1]
        # deformation = u_right − u_left; the gap closes when it falls below −d
        return self._link(left, right, tags, "ViscoelasticGap", contact.stiffness, contact.damping, -contact.gap)

    def _link(self, node_i: int, node_j: int, tags: _TagCounter, material: str, *parameters: float) -> int:
        """A zeroLength element of a new uniaxial material between two nodes; return its tag."""
        tag = tags.next()
        self.ops.uniaxialMaterial(material, tag, *parameters)
        self.ops.element("zeroLength", tag, node_i, node_j, "-mat", tag, "-dir", 1)
        return tag

    # ------------------------------------------------------------ analysis

    def _recorders(self, layout: _Layout, folder: Path) -> dict[str, Path]:
        ops = self.ops
        nodes = [layout.floor_nodes[0][-1], layout.base_nodes[0]]
        files = {"nodes": folder / "nodes.txt", "contacts": folder / "contacts.txt"}
        ops.recorder("Node", "-file", str(files["nodes"]), "-precision", 17, "-time", "-node", *nodes, "-dof", 1, "disp")
        if layout.contact_elements:
            ops.recorder("Element", "-file", str(files["contacts"]), "-precision", 17, "-ele", *layout.contact_elements, "basicForce")
        return files

    def _analyse(self) -> None:
        ops, motion = self.ops, self.scene.motion
        ops.timeSeries("Path", 1, "-dt", motion.dt, "-values", *np.asarray(motion.values, float))
        ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
        ops.constraints("Plain")
        ops.numberer("Plain")
        ops.system("FullGeneral")
        if any(building.yield_force is not None for building in self.scene.buildings):
            # Steel01's tangent jumps at yield and unloading: Newton at 1e-12 m fails to converge at some steps, a line search at 1e-9 m does
            ops.test("NormDispIncr", YIELDING_TOLERANCE, 200)
            ops.algorithm("NewtonLineSearch")
        else:
            ops.test("NormDispIncr", 1e-12, 50)
            ops.algorithm("Newton")
        ops.integrator("Newmark", 0.5, 0.25)
        ops.analysis("Transient")
        n_steps = (len(motion.times) - 1) * self.steps_per_sample
        if ops.analyze(n_steps, self.dt) != 0:
            raise RuntimeError(f"OpenSees analysis failed (dt = {self.dt:g} s)")

    def _outcome(self, layout: _Layout, files: dict[str, Path]) -> Outcome:
        nodes = np.loadtxt(files["nodes"], ndmin=2)
        samples = _at_samples(nodes[:, 0], self.scene.motion.times)
        top = np.concatenate([[0.0], nodes[samples, 1]])
        sliding = nodes[-1, 2] if layout.base_nodes[0] != _GROUND else 0.0
        impacts, peak = 0, 0.0
        if layout.contact_elements:
            compression = -np.loadtxt(files["contacts"], ndmin=2)  # ViscoelasticGap forces are negative in compression
            impacts, peak = _count_impacts(compression), float(max(compression.max(), 0.0))
        return Outcome(self.scene.motion.times.copy(), top, impacts, peak, float(sliding))


class _TagCounter:
    """Consecutive integer tags for nodes, materials and elements."""

    def __init__(self, start: int) -> None:
        self._next = start

    def next(self) -> int:
        tag, self._next = self._next, self._next + 1
        return tag


def _check_supported(scene: Scene) -> None:
    if not isinstance(scene.motion, SampledMotion) or scene.motion.interpolation != "linear":
        raise ValueError("the OpenSees model needs a sampled motion with linear interpolation")
    for contact in scene.contacts:
        if not contact.tensile or contact.gap <= 0.0:
            raise ValueError("ViscoelasticGap needs tensile contacts with a positive gap")
    for building in scene.buildings:
        if building.base is not None and building.base.mu_static != building.base.mu:
            raise ValueError("ElasticPP friction has one coefficient: mu_static must equal mu")
        if building.p_delta:
            raise ValueError("the OpenSees model has no P-Delta: p_delta must be false")
        initial = building.initial
        if initial is not None and any(np.any(np.asarray(v) != 0.0) for v in vars(initial).values()):
            raise ValueError("the OpenSees model starts at rest: initial conditions must be zero")
    if scene.study_compat:
        raise ValueError("OpenSees applies the impact forces to the whole building; study_compat is not representable")


def _at_samples(step_times: np.ndarray, sample_times: np.ndarray) -> np.ndarray:
    """Rows of the per-step record at the sample times after t = 0 (the record starts after the first step)."""
    index = np.searchsorted(step_times, sample_times[1:] - 1e-9)
    if np.any(np.abs(step_times[index] - sample_times[1:]) > 1e-7):
        raise RuntimeError("OpenSees record does not contain every sample time")
    return index


def _count_impacts(compression: np.ndarray) -> int:
    """Number of contact closures in per-step contact forces (rows: steps, columns: contacts)."""
    closed = compression != 0.0
    opened_before = np.vstack([np.ones((1, closed.shape[1]), bool), ~closed[:-1]])
    return int(np.count_nonzero(closed & opened_before))


def run_opensees(scene: Scene, dt: float) -> Outcome:
    """Analyse ``scene`` in OpenSeesPy with Newmark average acceleration at step ``dt``."""
    return OpenSeesModel(scene, dt).run()
