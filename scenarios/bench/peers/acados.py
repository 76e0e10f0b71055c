"""acados as a benchmark peer: rest-to-rest minimum time or minimum energy by multiple shooting.

The peer solves the problem every collocation row solves, written the way an acados user writes
it: state ``x = [q (4), ω (3)]`` (minimum time: plus ``T``, with the dynamics scaled by ``T`` on
``t ∈ [0, 1]`` and ``Ṫ = 0``), the rigid body ``I ω̇ = τ − ω × I ω``, piecewise-constant torques
in a box ``|τ_i| ≤ u_max,i``, ``N = 50`` shooting intervals, one explicit RK4 step per interval
(``ERK``, 4 stages), the terminal condition ``vec(q_f* ⊗ q(T)) = 0`` (and ``ω(T) = ω_f`` when the
final rate is fixed), exact Hessians, SQP with the partially condensing HPIPM QP solver. Minimum
time minimises ``T``; minimum energy ``Σ h ‖τ_k‖²`` (the integral of ``‖τ‖²`` of the
piecewise-constant torques, exactly) at the problem's fixed duration, the cost given to acados
divided by its scale (:func:`energy_scale`: acados's tolerances are absolute, and a cost of 1e-8
N² m² s met its 1e-8 at a point 21 % above the optimum); the objective is evaluated from the
returned trajectory, not read from acados (whose cost scaling differs between versions).

acados comes from the ``comma-deps-acados`` wheel, which vendors its own CasADi (3.6, without
IPOPT): it cannot share a process with slewbench's CasADi, and its libraries must be on
``LD_LIBRARY_PATH`` before the process starts. So the peer runs in a **worker process** under the
interpreter that has the wheel (``SLEWBENCH_ACADOS_PYTHON``, else the current interpreter when it
can import ``acados``), which this module starts as a script (it imports only the standard
library and NumPy at the top, never slewbench). The worker sets ``ACADOS_SOURCE_DIR``,
``ACADOS_PYTHON_INTERFACE_PATH``, ``TERA_PATH`` and ``LD_LIBRARY_PATH`` from the wheel and
re-executes itself once; it builds each problem in its own temporary directory and answers one
JSON request a line (``build``, ``solve``), so that a benchmark can alternate its solves with
ours. When no interpreter has acados the peer is skipped: :func:`available` says why.

Two faces: :data:`PEER` follows the peers' contract of :mod:`scenarios.bench.peers.base`
(``unavailable``, ``problem_error``, ``solve`` returning a ``PeerResult``; its guess is
``collocation``'s first start that every peer starts from,
:func:`~scenarios.bench.peers._shooting.first_start_guess`, and when acados stops at a QP failure
it builds once more with :data:`FALLBACK_OPTIONS`, both builds counted in the build time; it does so for
each HPIPM setting of :data:`QP_SETTINGS` and reports one, :meth:`AcadosBenchPeer._chosen`); :func:`solve` and
:class:`AcadosPeer` are the dict-level calls the side-by-side benchmarks use (one build, many
timed solves). ``time_s`` is the solve after the build, guess setting and ``reset`` included,
measured in the worker [s]; ``status`` is ``"ok"`` or acados's flag named; ``iterations`` its SQP
iterations; ``build_s`` the code generation and compilation [s].
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from typing import Any

import numpy as np

N = 50
"""Shooting intervals (the benchmarks' N)."""
ENV_PYTHON = "SLEWBENCH_ACADOS_PYTHON"
"""Environment variable naming the interpreter that has the ``comma-deps-acados`` wheel."""
ACADOS_STATUS = {0: "ok", 1: "nan_detected", 2: "maxiter", 3: "minstep", 4: "qp_failure", 5: "ready"}
"""acados's return flags, named."""
SOLVER_OPTIONS: dict[str, Any] = {"regularize_method": "PROJECT", "globalization": "MERIT_BACKTRACKING"}
"""acados options beyond the module docstring's (17 SQP iterations on Bilimoria & Wie 180°)."""
QP_SETTINGS: tuple[dict[str, Any], ...] = ({}, {"qp_solver_iter_max": 8, "qp_solver_warm_start": 1})
"""HPIPM settings ``slewbench bench``'s peer tries on every problem (each over :data:`SOLVER_OPTIONS`,
and over :data:`FALLBACK_OPTIONS` after a QP failure): HPIPM's defaults (at most 50 interior-point
iterations per QP) and at most 8, warm-started from the last QP. Of the converged solves, those
within :data:`SAME_OBJECTIVE` of the lowest objective compete, the faster by a first solve is
reported with the time of a second solve. Neither setting is best everywhere (2026-12-04,
``slewbench bench --planners acados``, the second against the first): Bilimoria & Wie 180° 59
against 136 ms, the full inertia 45 against 195 ms, but 90° 170 against 96 ms and 45° 229 against
192 ms, the same objectives; a user tuning acados per problem would keep the faster, so the peer
does."""
SAME_OBJECTIVE = 1e-6
"""Relative difference within which two settings' objectives are the same optimum (the settings
then compete on time; a lower optimum wins whatever its time)."""
FALLBACK_OPTIONS: dict[str, Any] = {"regularize_method": "MIRROR", "levenberg_marquardt": 0.1}
"""Options of the second build after a QP failure: the full-inertia case (150° about [1, 1, 1])
stops at a QP failure in SQP iteration 2 under :data:`SOLVER_OPTIONS` (and under MIRROR,
CONVEXIFY, a Levenberg-Marquardt term of 1e-3 or 200 QP iterations); these reach 7.68339 in 64."""


# -- the parent side (slewbench's interpreter) -----------------------------------------------------
def interpreter() -> tuple[str | None, str]:
    """The interpreter that runs the worker, or ``None`` and why there is none.

    Returns
    -------
    tuple
        ``(path or None, note)``.
    """
    configured = os.environ.get(ENV_PYTHON)
    if configured:
        if os.path.isfile(configured) and os.access(configured, os.X_OK):
            return configured, f"acados from {configured}"
        return None, f"{ENV_PYTHON}={configured!r} is not an executable file"
    import importlib.util

    if importlib.util.find_spec("acados") is not None:
        return sys.executable, "acados from the current interpreter"
    return None, (f"acados is not installed (pip install comma-deps-acados into a separate environment and "
                  f"point {ENV_PYTHON} at its python)")


def available() -> tuple[bool, str]:
    """Whether the peer can run, and a note saying from where or why not.

    Returns
    -------
    tuple
        ``(bool, note)``.
    """
    path, note = interpreter()
    return path is not None, note


def problem_data(problem: Any, objective: str, intervals: int = N, guess: tuple[Any, float] | None = None,
                 options: dict[str, Any] | None = None) -> dict:
    """The JSON request that describes a problem to the worker.

    Parameters
    ----------
    problem : planners.ManeuverProblem
        A rest-to-rest (or any initial rate) problem of a rigid spacecraft with torquers.
    objective : ``"min_time"`` or ``"min_energy"``.
    intervals : int
        Shooting intervals.
    guess : tuple or None
        ``(states (7, intervals + 1), T0 [s])``: the initial guess (``None``: the quaternion
        interpolated along the eigenaxis at zero rate, T0 the problem's duration).
    options : dict or None
        acados solver options overriding :data:`SOLVER_OPTIONS`.

    Returns
    -------
    dict
        Inertia [kg m²], torque bound [N m], initial state, target, duration [s], objective, N, guess.
    """
    if objective not in ("min_time", "min_energy"):
        raise ValueError(f"objective must be 'min_time' or 'min_energy', got {objective!r}")
    torquers = problem.spacecraft.torquers
    if torquers is None or problem.spacecraft.wheels is not None:
        raise ValueError("the acados peer takes a rigid spacecraft with torquers only")
    data: dict[str, Any] = {
        "inertia": np.asarray(problem.spacecraft.inertia, dtype=float).tolist(),
        "u_max": np.broadcast_to(np.asarray(torquers.max_torque, dtype=float), (3,)).tolist(),
        "x0": np.asarray(problem.initial_state, dtype=float)[:7].tolist(),
        "qf": np.asarray(problem.qf, dtype=float).tolist(),
        "omegaf": None if problem.omegaf is None else np.asarray(problem.omegaf, dtype=float).tolist(),
        "duration": float(problem.duration), "objective": objective, "N": int(intervals)}
    if guess is not None:
        states, T0 = guess
        data["guess"] = {"states": np.asarray(states, dtype=float).tolist(), "T": float(T0)}
    if options:
        data["options"] = dict(options)
    return data


class AcadosPeer:
    """A worker process with acados: build a problem once, then solve it as often as wanted.

    Raises ``RuntimeError`` when acados is not available (see :func:`available`). Use as a context
    manager, or call :meth:`close`.
    """

    def __init__(self) -> None:
        path, note = interpreter()
        if path is None:
            raise RuntimeError(note)
        self.note = note
        # What acados, its code generator and gcc print (version warnings on every build) goes to a
        # log, not to the user's terminal; a failure quotes its end (:meth:`_log_tail`).
        self._log = tempfile.TemporaryFile(mode="w+b")  # noqa: SIM115 (lives as long as the worker; close())
        self._process = subprocess.Popen([path, os.path.abspath(__file__), "--worker"], stdin=subprocess.PIPE,
                                         stdout=subprocess.PIPE, stderr=self._log, text=True, bufsize=1)

    def _log_tail(self, size: int = 2000) -> str:
        """The last ``size`` characters the worker printed (for an error message)."""
        self._log.flush()
        self._log.seek(0, os.SEEK_END)
        end = self._log.tell()
        self._log.seek(max(0, end - size))
        text = self._log.read().decode(errors="replace").strip()
        return f"\nthe worker's last output:\n{text}" if text else ""

    def _ask(self, request: dict) -> dict:
        assert self._process.stdin is not None and self._process.stdout is not None
        try:
            self._process.stdin.write(json.dumps(request) + "\n")
            self._process.stdin.flush()
        except BrokenPipeError:  # it ended before reading
            line = ""
        else:
            line = self._process.stdout.readline()
        if not line:
            raise RuntimeError(f"the acados worker ended (exit {self._process.wait(timeout=30)}){self._log_tail()}")
        answer = json.loads(line)
        if "error" in answer:
            raise RuntimeError(f"acados worker: {answer['error']}{self._log_tail()}")
        return answer

    def build(self, problem: Any, objective: str, intervals: int = N,
              guess: tuple[Any, float] | None = None, options: dict[str, Any] | None = None) -> float:
        """Generate and compile the solver of a problem (replacing the previous one).

        Parameters
        ----------
        problem, objective, intervals, guess, options
            As in :func:`problem_data`.

        Returns
        -------
        float
            The build's wall time [s] (code generation and compilation), measured in the worker.
        """
        return float(self._ask({"op": "build", **problem_data(problem, objective, intervals, guess, options)})["build_s"])

    def solve(self) -> dict:
        """Solve the built problem from its guess.

        Returns
        -------
        dict
            ``objective``, ``T`` [s], ``time_s`` [s] (in the worker: setting the guess and solving),
            ``status``, ``iterations``.
        """
        return self._ask({"op": "solve"})

    def close(self) -> None:
        """End the worker."""
        assert self._process.stdin is not None and self._process.stdout is not None
        try:
            self._process.stdin.close()  # the worker ends at the end of its input
        except BrokenPipeError:  # it had ended already
            pass
        self._process.wait(timeout=30)
        self._process.stdout.close()
        self._log.close()

    def __enter__(self) -> AcadosPeer:  # noqa: PYI034 (no Self on Python 3.10)
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def solve(problem: Any, objective: str = "min_time", intervals: int = N,
          guess: tuple[Any, float] | None = None, options: dict[str, Any] | None = None) -> dict:
    """Build and solve one problem with acados (the peers' contract).

    Parameters
    ----------
    problem, objective, intervals, guess, options
        As in :func:`problem_data`.

    Returns
    -------
    dict
        ``objective``, ``T`` [s], ``time_s`` [s], ``status``, ``iterations``, ``build_s`` [s],
        ``note``; or ``skipped: True`` with the reason in ``note``.
    """
    ok, note = available()
    if not ok:
        return {"skipped": True, "note": note}
    with AcadosPeer() as peer:
        build_s = peer.build(problem, objective, intervals, guess, options)
        result = peer.solve()
    return {**result, "build_s": build_s, "note": note, "skipped": False}


class AcadosBenchPeer:
    """The acados peer of ``slewbench bench`` (the contract of :mod:`scenarios.bench.peers.base`).

    One worker process serves every problem of a run (started on first use, ended at exit).
    """

    name = "acados"

    def __init__(self) -> None:
        self._worker: AcadosPeer | None = None

    def unavailable(self) -> str | None:
        """Why the peer cannot run here (``None``: it can).

        Returns
        -------
        str or None
            The reason (no interpreter with acados), or ``None``.
        """
        ok, note = available()
        return None if ok else note

    def version(self) -> str:
        """The ``comma-deps-acados`` wheel's version, asked of the interpreter that runs the worker.

        Returns
        -------
        str
            ``"comma-deps-acados <version>"``, or why it is not known.
        """
        path, note = interpreter()
        if path is None:
            return f"unknown ({note})"
        query = "import importlib.metadata as m; print(m.version('comma-deps-acados'))"
        try:
            answer = subprocess.run([path, "-c", query], capture_output=True, text=True, timeout=60, check=True)
        except (OSError, subprocess.SubprocessError) as error:
            return f"unknown ({type(error).__name__})"
        return f"comma-deps-acados {answer.stdout.strip()}"

    def problem_error(self, problem: Any, objective: str) -> str | None:
        """Why the peer cannot express the problem (``None``: it can).

        Parameters
        ----------
        problem : ManeuverProblem
            The problem.
        objective : str
            ``"min_time"`` or ``"min_energy"``.

        Returns
        -------
        str or None
            The reason, or ``None``.
        """
        from scenarios.bench.peers.base import box_torque_problem_error

        return box_torque_problem_error(problem, objective)

    def solve(self, problem: Any, objective: str) -> Any:
        """Build (again with :data:`FALLBACK_OPTIONS` after a QP failure) and solve from ``collocation``'s
        first start (:func:`~scenarios.bench.peers._shooting.first_start_guess`) under each HPIPM
        setting of :data:`QP_SETTINGS`, and report one (:meth:`_chosen`).

        Parameters
        ----------
        problem : ManeuverProblem
            A problem :meth:`problem_error` accepts.
        objective : str
            ``"min_time"`` or ``"min_energy"``.

        Returns
        -------
        PeerResult
            The objective reached (``None`` when acados failed), the reported solve's time in the
            worker [s], ``"ok"`` or ``"failed"``, the SQP iterations, the start, acados's status and
            the QP setting reported, the build time [s] (every build); ``extra``: the options of
            the reported solve, the final time [s], the start and ``tried`` (per setting: its
            options, status, the choosing and the reported solve's times [s], SQP iterations,
            objective, or the error that stopped it; ``None`` for a value that is not finite).
        """
        from scenarios.bench.peers._shooting import first_start_guess
        from scenarios.bench.peers.base import PeerResult

        guess = first_start_guess(problem, objective, N)
        build, tried = 0.0, []
        for setting in QP_SETTINGS:
            entry = self._solve_setting(problem, objective, guess, setting)
            build += entry.pop("build_s")
            tried.append(entry)
        record = [{"options": entry["options"], **({"error": entry["error"]} if "error" in entry else {
            "status": entry["answer"]["status"], "choice_time_s": _finite(entry["first"]["time_s"]),
            "time_s": _finite(entry["answer"]["time_s"]), "iterations": entry["answer"]["iterations"],
            "objective": _finite(entry["answer"]["objective"])})} for entry in tried]
        chosen, choice = self._chosen(tried)
        if chosen is None:
            errors = "; ".join(f"{_setting_name(entry['options'])}: {entry['error']}" for entry in tried)
            return PeerResult(None, 0.0, "failed", None, f"{guess.start}; {errors}", build or None,
                              {"start": guess.start, "tried": record})
        options, answer = chosen["options"], chosen["answer"]
        ok = answer["status"] == "ok"
        return PeerResult(answer["objective"] if ok else None, answer["time_s"], "ok" if ok else "failed",
                          answer["iterations"],
                          f"{guess.start}; acados: {answer['status']} ({_setting_name(options)}; {choice})", build,
                          {"options": dict(options), "T": _finite(answer["T"]), "start": guess.start, "tried": record},
                          answer.get("cpu_s"))

    def _solve_setting(self, problem: Any, objective: str, guess: Any, setting: dict[str, Any]) -> dict[str, Any]:
        """Build and solve under one HPIPM setting (over :data:`FALLBACK_OPTIONS` after a QP failure).
        A converged solve is solved again: the first chooses among the settings, the second is
        the one reported, so that the time reported is not the one the choice was made on.

        Returns
        -------
        dict
            ``options``, ``build_s`` [s] and ``first`` and ``answer`` (the worker's answers), or
            ``error`` where the worker raised (it is closed if it died; the next setting starts another).
        """
        import atexit

        from scenarios.bench.peers.base import torque_bounds

        build = 0.0
        options: dict[str, Any] = {}
        try:
            for base in (SOLVER_OPTIONS, FALLBACK_OPTIONS):
                options = {**base, **setting}
                data = problem_data(problem, objective, N, (guess.states, guess.duration), options)
                data["u_max"] = np.asarray(torque_bounds(problem), dtype=float).tolist()  # the actuator margin applied
                if self._worker is None:
                    self._worker = AcadosPeer()
                    atexit.register(self._worker.close)
                worker = self._worker
                build += float(worker._ask({"op": "build", **data})["build_s"])
                first = worker.solve()
                if first["status"] != "qp_failure":
                    break
            answer = worker.solve() if first["status"] == "ok" else first
        except RuntimeError as error:
            if self._worker is not None and self._worker._process.poll() is not None:  # it died
                self._worker.close()
                self._worker = None
            return {"options": options, "build_s": build, "error": str(error)}
        return {"options": options, "build_s": build, "first": first, "answer": answer}

    @staticmethod
    def _chosen(tried: list[dict[str, Any]]) -> tuple[dict[str, Any] | None, str]:
        """The setting reported, and why: among the converged solves those within
        :data:`SAME_OBJECTIVE` of the lowest objective, the fastest by its first solve; where none
        converged, the first setting that answered; ``None`` where every setting raised."""
        answered = [entry for entry in tried if "answer" in entry]
        converged = [entry for entry in answered if entry["answer"]["status"] == "ok"]
        if not converged:
            return (answered[0] if answered else None), f"none of {len(tried)} QP settings converged"
        best = min(entry["answer"]["objective"] for entry in converged)
        same = [entry for entry in converged if entry["answer"]["objective"] <= best + SAME_OBJECTIVE * abs(best)]
        chosen = min(same, key=lambda entry: entry["first"]["time_s"])
        others = [f"{_setting_name(entry['options'])}: {entry['error']}" for entry in tried if "error" in entry]
        if len(converged) == 1:
            why = f"the only one of {len(tried)} QP settings that converged"
        elif len(same) == len(converged):
            why = f"the faster of {len(converged)} converged QP settings"
        else:
            worse = ", ".join(f"{entry['answer']['objective']:.8g}" for entry in converged if entry not in same)
            why = f"the lowest objective of {len(converged)} converged QP settings (the others {worse})"
        return chosen, why + "".join(f"; {other}" for other in others)


def _setting_name(options: dict[str, Any]) -> str:
    """An HPIPM setting in words: its ``qp_solver`` options, or HPIPM's defaults."""
    return ", ".join(f"{name} {value}" for name, value in options.items() if name.startswith("qp_solver")) or \
        "HPIPM's defaults"


def _finite(value: Any) -> float | None:
    """``value`` as a float, ``None`` where it is not finite (JSON has no NaN)."""
    return float(value) if value is not None and np.isfinite(value) else None


PEER = AcadosBenchPeer()
"""The peer ``slewbench bench`` runs."""


# -- the worker side (the interpreter with the acados wheel) --------------------------------------
def _environment() -> dict[str, str] | None:
    """The environment acados needs, or ``None`` when the process already has it."""
    import acados  # the comma-deps-acados wheel, in its own environment

    root = os.path.dirname(acados.__file__)
    wanted = {"ACADOS_SOURCE_DIR": acados.DIR, "ACADOS_PYTHON_INTERFACE_PATH": os.path.join(root, "acados_template"),
              "TERA_PATH": acados.TERA_PATH}
    library = acados.LIB_DIR
    paths = os.environ.get("LD_LIBRARY_PATH", "").split(os.pathsep)
    if all(os.environ.get(k) == v for k, v in wanted.items()) and library in paths:
        return None
    env = dict(os.environ, **wanted)
    env["LD_LIBRARY_PATH"] = os.pathsep.join([library] + [p for p in paths if p])
    return env


def _rigid_body(ca: Any, inertia: Any, x: Any, u: Any) -> Any:
    q, w = x[:4], x[4:7]
    I = ca.DM(inertia)
    qdot = 0.5 * ca.vertcat(-ca.dot(q[1:], w), q[0] * w + ca.cross(q[1:], w))
    return ca.vertcat(qdot, ca.solve(I, u - ca.cross(w, ca.mtimes(I, w))))


def _guess(data: dict) -> tuple[np.ndarray, float]:
    if "guess" in data:
        return np.asarray(data["guess"]["states"], dtype=float), float(data["guess"]["T"])
    n = data["N"]
    q0, qf = np.asarray(data["x0"][:4]), np.asarray(data["qf"])
    if np.dot(q0, qf) < 0:
        qf = -qf
    angle = np.arccos(np.clip(np.dot(q0, qf), -1.0, 1.0))
    s = np.linspace(0.0, 1.0, n + 1)
    if angle < 1e-9:
        q = np.outer(q0, np.ones(n + 1))
    else:
        q = (np.outer(q0, np.sin((1 - s) * angle)) + np.outer(qf, np.sin(s * angle))) / np.sin(angle)
    return np.vstack([q, np.zeros((3, n + 1))]), float(data["duration"])


def energy_scale(data: dict) -> float:
    """The scale of a minimum-energy cost [N² m² s], what acados minimises ``Σ h ‖τ_k‖²`` over: the
    energy of the guess (the torques its node rates imply, ``I (ω_k+1 − ω_k) / h + ω_k × I ω_k``
    held over each interval), else of the single-axis rest-to-rest slew by the guess's angle
    ``12 λ_max² θ² / T³`` (λ_max the largest principal inertia), else 1.

    acados's stationarity, feasibility and complementarity tolerances (``tol``) are absolute: on
    the natural-motion problem (optimum 5.85e-8) the unscaled cost stopped at 7.09e-8 with acados's
    flag "ok" after 171 iterations; divided by this scale (the cost of order 1) it reaches the
    optimum FATROP and rockit reach from the same start.

    Parameters
    ----------
    data : dict
        A request of :func:`problem_data` (inertia, duration, N, guess or target).

    Returns
    -------
    float
        A positive energy [N² m² s].
    """
    states, _ = _guess(data)
    inertia = np.asarray(data["inertia"], dtype=float)
    n = int(data["N"])
    h = float(data["duration"]) / n
    omega = states[4:7].T
    torque = (np.diff(omega, axis=0) / h) @ inertia.T + np.cross(omega[:-1], omega[:-1] @ inertia.T)
    energy = float(h * np.sum(torque ** 2))
    if energy > 0.0 and np.isfinite(energy):
        return energy
    q0, qf = np.asarray(data["x0"][:4], dtype=float), np.asarray(data["qf"], dtype=float)
    angle = 2.0 * float(np.arccos(min(1.0, abs(float(np.dot(q0, qf))))))
    slew = 12.0 * float(np.max(np.linalg.eigvalsh(inertia))) ** 2 * angle ** 2 / float(data["duration"]) ** 3
    return slew if slew > 0.0 else 1.0


class _Worker:
    def __init__(self) -> None:
        self.count = 0
        self.solver: Any = None
        self.data: dict = {}
        self.home = tempfile.mkdtemp(prefix="slewbench-acados-")

    def build(self, data: dict) -> dict:
        import casadi as ca
        from acados_template import AcadosModel, AcadosOcp, AcadosOcpSolver

        self.count += 1
        free = data["objective"] == "min_time"
        n, u_max = data["N"], np.asarray(data["u_max"])
        x = ca.SX.sym("x", 8 if free else 7)
        u = ca.SX.sym("u", 3)
        body = _rigid_body(ca, data["inertia"], x, u)
        model = AcadosModel()
        model.name = f"slewbench_{os.getpid()}_{self.count}"
        model.x, model.u = x, u
        model.xdot = ca.SX.sym("xdot", x.numel())
        model.f_expl_expr = ca.vertcat(x[7] * body, 0) if free else body
        qf = ca.DM(data["qf"])
        error = qf[0] * x[1:4] - x[0] * qf[1:] - ca.cross(qf[1:], x[1:4])  # vec(q_f* ⊗ q)
        terminal = [error] + ([x[4:7] - ca.DM(data["omegaf"])] if data["omegaf"] is not None else [])
        model.con_h_expr_e = ca.vertcat(*terminal)
        model.cost_expr_ext_cost = 0 if free else ca.dot(u, u) / energy_scale(data)  # of order 1
        model.cost_expr_ext_cost_e = x[7] if free else 0
        ocp = AcadosOcp()
        ocp.model = model
        ocp.dims.N = n
        ocp.solver_options.tf = 1.0 if free else data["duration"]
        ocp.cost.cost_type = "EXTERNAL"
        ocp.cost.cost_type_e = "EXTERNAL"
        ocp.constraints.lbu, ocp.constraints.ubu, ocp.constraints.idxbu = -u_max, u_max, np.arange(3)
        x0 = np.asarray(data["x0"], dtype=float)
        ocp.constraints.idxbx_0 = np.arange(7)
        ocp.constraints.lbx_0 = ocp.constraints.ubx_0 = x0
        ocp.constraints.idxbxe_0 = np.arange(7)
        if free:
            ocp.constraints.idxbx = np.array([7])
            ocp.constraints.lbx, ocp.constraints.ubx = np.array([1e-3 * data["duration"]]), np.array([data["duration"]])
        nh = int(model.con_h_expr_e.numel())
        ocp.constraints.lh_e = ocp.constraints.uh_e = np.zeros(nh)
        options = ocp.solver_options
        options.integrator_type = "ERK"
        options.sim_method_num_stages = 4
        options.sim_method_num_steps = 1
        options.hessian_approx = "EXACT"
        options.nlp_solver_type = "SQP"
        options.qp_solver = "PARTIAL_CONDENSING_HPIPM"
        options.nlp_solver_max_iter = 500
        options.tol = 1e-8
        options.print_level = 0
        for name, value in {**SOLVER_OPTIONS, **data.get("options", {})}.items():
            setattr(options, name, value)
        ocp.code_export_directory = os.path.join(self.home, model.name)
        begin = time.perf_counter()
        cwd = os.getcwd()
        os.chdir(self.home)
        try:
            self.solver = AcadosOcpSolver(ocp, json_file=os.path.join(self.home, model.name + ".json"),
                                          verbose=False)
        finally:
            os.chdir(cwd)
        self.data = data
        return {"build_s": time.perf_counter() - begin}

    def solve(self) -> dict:
        data, solver = self.data, self.solver
        if solver is None:
            raise RuntimeError("solve before build")
        free, n = data["objective"] == "min_time", data["N"]
        states, T0 = _guess(data)
        begin, cpu = time.perf_counter(), time.process_time()
        solver.reset()  # no multipliers or QP memory from the previous solve: every solve starts alike
        for k in range(n + 1):
            solver.set(k, "x", np.append(states[:, k], T0) if free else states[:, k])
            if k < n:
                solver.set(k, "u", np.zeros(3))
        status = int(solver.solve())
        elapsed, cpu = time.perf_counter() - begin, time.process_time() - cpu
        X = np.array([solver.get(k, "x") for k in range(n + 1)])
        U = np.array([solver.get(k, "u") for k in range(n)])
        T = float(X[-1, 7]) if free else float(data["duration"])
        objective = T if free else float(np.sum(U ** 2) * T / n)
        return {"objective": objective, "T": T, "time_s": elapsed, "cpu_s": cpu, "status": ACADOS_STATUS.get(status, f"flag_{status}"),
                "iterations": int(np.ravel(solver.get_stats("sqp_iter"))[0])}


def _serve() -> None:
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path[:] = [p for p in sys.path if os.path.abspath(p or ".") != here]  # "acados" is the wheel, not this file
    env = _environment()
    if env is not None:  # the libraries must be on the path before the process starts
        os.execve(sys.executable, [sys.executable, os.path.abspath(__file__), "--worker"], env)
    sys.path.append(os.path.dirname(os.environ["ACADOS_PYTHON_INTERFACE_PATH"]))  # the wheel's acados_template
    worker = _Worker()
    # acados, its compiler and its C code print to file descriptor 1: answers go to a copy of it,
    # and 1 itself now points at stderr
    answers = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    import shutil

    try:
        for line in sys.stdin:
            try:
                request = json.loads(line)
                op = request.pop("op")
                answer = worker.build(request) if op == "build" else worker.solve()
            except Exception as error:  # noqa: BLE001 (any failure is reported to the parent, which raises it)
                answer = {"error": f"{type(error).__name__}: {error}"}
            answers.write(json.dumps(answer) + "\n")
            answers.flush()
    finally:  # also on Ctrl-C (the terminal sends it to the worker too) or a closed pipe
        shutil.rmtree(worker.home, ignore_errors=True)  # the generated code and libraries of this run


if __name__ == "__main__" and sys.argv[1:] == ["--worker"]:
    _serve()
