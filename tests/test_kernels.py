"""Generated kernels (pinmech/solve/kernels.py, kernel_build.py, csrc/kernel.cpp): the
kinematic passes as Pinocchio's algorithms specialised to the model, compiled and cached.

Checks, each against something that is not the kernel:
- every joint kind the core takes: with the kernel on, the closure rows are Pinocchio's own
  frame placements R_P^T (p_C - p_P) (1e-15, as tests/test_core.py's), the Jacobian their
  central difference (h = 1e-6: truncation h^2 ~ 1e-12, rounding eps / h ~ 1e-10; 1e-8);
- every bundled scene with loops: the kernel's closure residual, Jacobian and drift equal
  the generic passes' to 1e-13 of their size. The two run the same operations on the same
  numbers in another order: each output is a sum of at most a few hundred products of
  numbers of the model's size (lengths to 1 m, rotations to 1, rates to 10), so the two
  differ by a few hundred ulps of that size at most (300 x 2.2e-16 ~ 7e-14 < 1e-13);
- the closed forms of tests/test_bundled_models.py (four-bar, slider-crank) with the kernel on;
- a changed dimension is used at the next call with no new kernel; a study, a grid, a
  workspace grid and a six-bar search make one kernel in all (generations counted);
- a joint changed in place (prismatic to revolute) never runs the old kernel: the core
  refuses it, the solver's next call makes a fresh one, checked against Pinocchio;
- the kernel's name changes with each joint type, axis, pitch, mimic ratio, not with a length;
- "auto": the kernel for a long run where the generator is built, else the generic passes;
- no compiler: one line names it, the generic passes run; the cache refuses what it did not
  write, and processes asking at once build a file once (its lock);
- every bundled scene's analysis on the kernel equals the generic one to 1e-13 of its size.
"""

from __future__ import annotations

import multiprocessing
import os
import stat
import sys
import tempfile
import time

import numpy as np
import pinocchio as pin
import pytest

import closed_form
import pinmech
import pinmech.solve.core as core
from pinmech.io.sweep import Sweep
from pinmech.solve import kernel_build, kernels
from pinmech.solve.loops import LoopSolver
from tests.conftest import MODELS
from tests.test_core import LOOP_SCENES, _relative_position, _two_chains



@pytest.fixture(scope="session")
def kernels_here():
    """The kernel generator, built once per test session (and once per machine: the user
    cache keeps it; workers of `pytest -n` that ask at once wait on its lock, one builds);
    the test is skipped, with the one-line reason, where it cannot be built here."""
    start = time.perf_counter()
    try:
        path = kernel_build.generator_path()
    except kernel_build.KernelUnavailable as why:
        pytest.skip(f"no generated kernels here: {why}")
    seconds = time.perf_counter() - start
    if seconds > 1.0:
        print(f"\nthe kernel generator was built in {seconds:.0f} s", file=sys.stderr)
    return path


needs_kernels = pytest.mark.usefixtures("kernels_here")

#: Every bundled scene (models/scenes); LOOPS: those with loops and drivers (a sweep; the delta has none).
SCENES = sorted(p.name for p in (MODELS / "scenes").glob("*.toml") if not p.name.endswith(".hand.toml"))
LOOPS = sorted(set(LOOP_SCENES) | {"crank_shaper.toml", "four_bar_coupler_point.toml", "jansen_leg.toml",
                                   "leg_mjcf.toml", "stephenson_params.toml", "watt_params.toml"})

KINDS = ["helical", "helical_z", "universal", "ellipsoid", "spherical_zyx", "spherical", "planar", "free_flyer",
         "translation", "prismatic_unaligned", "composite", "mimic"]


def _with_kernel(compiled, model):
    path = kernels.attach(compiled, model, "generated")
    assert path is not None and compiled.kernel_path == path
    return compiled


@needs_kernels
@pytest.mark.parametrize("kind", KINDS)
def test_every_joint_kind_on_the_kernel_meets_pinocchio_and_finite_differences(kind):
    """The joint kinds of tests/test_core.py's test_the_core_serves_every_joint_kind, with the
    kernel on: closure rows against Pinocchio's own frame placements, Jacobian against their
    central difference (the module's docstring gives the tolerances)."""
    model, closure = _two_chains(kind)
    compiled = _with_kernel(core.compile_loops(model, [closure], np.ones(model.nv))[0], model)
    rng, h = np.random.default_rng(11), 1e-6
    for _ in range(3):
        q = pin.integrate(model, pin.neutral(model), rng.uniform(-1.0, 1.0, model.nv))
        np.testing.assert_allclose(compiled.residual(q), _relative_position(model, closure, q), rtol=0, atol=1e-15)
        J = compiled.jacobian(False)
        for k in range(model.nv):
            e = np.zeros(model.nv)
            e[k] = h
            fd = (_relative_position(model, closure, pin.integrate(model, q, e))
                  - _relative_position(model, closure, pin.integrate(model, q, -e))) / (2 * h)
            np.testing.assert_allclose(J[:, k], fd, rtol=0, atol=1e-8, err_msg=f"column {k}")


@needs_kernels
@pytest.mark.parametrize("kind", KINDS)
def test_every_joint_kind_on_the_kernel_equals_the_generic_passes(kind):
    """Residual, Jacobian and drift with and without the kernel, at seeded poses and rates:
    equal to 1e-13 of their size (the module's docstring derives the bound)."""
    model, closure = _two_chains(kind)
    generic = core.compile_loops(model, [closure], np.ones(model.nv))[0]
    generated = _with_kernel(core.compile_loops(model, [closure], np.ones(model.nv))[0], model)
    _same_passes(model, generic, generated, np.random.default_rng(5))


def _same_passes(model, generic, generated, rng, poses=3):
    for _ in range(poses):
        q = pin.integrate(model, pin.neutral(model), rng.uniform(-1.0, 1.0, model.nv))
        v = rng.normal(size=model.nv)
        for name, a, b in (("residual", generic.residual(q), generated.residual(q)),
                           ("jacobian", generic.jacobian(True), generated.jacobian(True)),
                           ("drift", generic.drift(q, v), generated.drift(q, v))):
            size = max(1.0, float(np.max(np.abs(a))))
            np.testing.assert_allclose(b, a, rtol=0, atol=1e-13 * size, err_msg=name)


@needs_kernels
@pytest.mark.parametrize("scene", LOOPS)
def test_every_bundled_model_on_the_kernel_equals_the_generic_passes(scenes_dir, scene):
    """Every bundled scene with loops: the kernel's passes give the generic residual,
    Jacobian and drift to 1e-13 of their size, at poses near the scene's own."""
    path = scenes_dir / scene
    if not path.is_file():
        pytest.skip(f"{scene} is not bundled")
    solver = Sweep.from_scene(pinmech.Scene.load(path)).solver
    generic = core.core_for(solver)
    generated = _with_kernel(core.compile_loops(solver.model, solver.mechanism.closures,
                                                solver.mechanism.velocity_scale(), drv_v=solver._drv_v,
                                                dep_v=solver._dep_v, drv_q=solver._drv_q,
                                                blocks=solver.structure.blocks)[0], solver.model)
    _same_passes(solver.model, generic, generated, np.random.default_rng(3))


@needs_kernels
def test_the_four_bar_on_the_kernel_meets_its_closed_form(scenes_dir):
    """tests/test_bundled_models.py's four-bar check, with [solver] kernel = "generated"."""
    sweep = Sweep.from_scene(pinmech.Scene.load(scenes_dir / "four_bar.toml", ['solver.kernel="generated"']))
    assert sweep.solver.kernel == "generated"
    values = sweep.default_values(91)
    poses = list(sweep.poses(values))
    assert core.core_for(sweep.solver).kernel_path
    cf = closed_form.four_bar(values, 4 * np.pi, 0.0, 0.04, 0.12, 0.08, 0.10, branch=1)
    links = [p.motion.links for p in poses]
    _close([m["rocker"].angular_velocity[2] for m in links], cf.omega4)
    _close([m["rocker"].angular_acceleration[2] for m in links], cf.alpha4)
    _close([p.motion.points["B_pin"].acceleration[:2] for p in poses], cf.aB)


@needs_kernels
def test_the_slider_crank_on_the_kernel_meets_its_closed_form(scenes_dir):
    sweep = Sweep.from_scene(pinmech.Scene.load(scenes_dir / "slider_crank.toml", ['solver.kernel="generated"']))
    values = sweep.default_values(91)
    poses = list(sweep.poses(values))
    assert core.core_for(sweep.solver).kernel_path
    cf = closed_form.slider_crank(values, 100 * np.pi, 0.0, 0.05, 0.15, 0.01, branch=1)
    _close([p.motion.joints["slide"].q for p in poses], cf.x_B)
    _close([p.motion.joints["slide"].v for p in poses], cf.v_B)
    _close([p.motion.joints["slide"].a for p in poses], cf.a_B)


def _close(ours, theirs):
    """tests/test_bundled_models.py's bound: 1e-10 of the quantity's largest magnitude."""
    theirs = np.asarray(theirs, dtype=float)
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-10 * np.abs(theirs).max())


@needs_kernels
def test_a_changed_dimension_is_used_with_the_same_kernel(models_dir):
    """A joint placement changed in the model (a study's variant) is read at the next call:
    the residual is Pinocchio's frame placements for the new length, and no kernel is built."""
    mech = pinmech.Mechanism.from_urdf(models_dir / "four_bar.urdf")
    closure = mech.closures[0]
    model = mech.model
    compiled = _with_kernel(core.compile_loops(model, [closure], np.ones(model.nv))[0], model)
    first = compiled.kernel_path
    q = pin.integrate(model, pin.neutral(model), np.array([0.3, -0.2, 0.5]))
    j = model.frames[closure.child_frame].parentJoint
    model.jointPlacements[j] = pin.SE3(np.eye(3), model.jointPlacements[j].translation + np.array([0.013, 0, 0]))
    before = kernel_build.build_kernel(model)
    assert before.cached and str(before.path) == first
    np.testing.assert_allclose(compiled.errors6(q)[0, :3], _relative_position(model, closure, q), rtol=0, atol=1e-15)


def test_the_scene_and_api_refuse_an_unknown_kernel(scenes_dir):
    with pytest.raises(pinmech.SceneError, match="kernel"):
        Sweep.from_scene(pinmech.Scene.load(scenes_dir / "four_bar.toml", ['solver.kernel="fast"']))
    mech = pinmech.Mechanism.from_urdf(scenes_dir.parent / "four_bar.urdf")
    with pytest.raises(pinmech.OptionError, match="generic, generated"):
        LoopSolver(mech, ["O2"], kernel="fast")


@needs_kernels
def test_the_cache_rebuilds_a_kernel_it_did_not_write(models_dir):
    """A cached kernel whose bytes no longer match its record, or that is a link, is built
    anew; the folder is the user's alone (0700)."""
    mech = pinmech.Mechanism.from_urdf(models_dir / "four_bar.urdf")
    # a frame of its own makes this kernel this test's alone: the other tests' four-bar
    # kernel, which `pytest -n` workers may be reading now, is left whole
    mech.model.addFrame(pin.Frame("only_the_cache_test", 0, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    build = kernel_build.build_kernel(mech.model)
    assert stat.S_IMODE(os.stat(build.path.parent).st_mode) == 0o700
    assert kernel_build.build_kernel(mech.model).cached
    with open(build.path, "ab") as f:
        f.write(b"\0")
    again = kernel_build.build_kernel(mech.model)
    assert not again.cached and again.path == build.path
    target = build.path.with_name("elsewhere.so")
    os.replace(build.path, target)
    os.symlink(target, build.path)
    try:
        third = kernel_build.build_kernel(mech.model)
        assert not third.cached and not os.path.islink(third.path)
    finally:
        target.unlink(missing_ok=True)


@needs_kernels
def test_the_arm_of_text_17_110_on_the_kernel_meets_cramers_rule(scenes_dir):
    """tests/test_planar_arm.py's check (rtol 1e-10) with [solver] kernel = "generated": the
    rate solve (RateSolver) runs its passes on the kernel."""
    from pinmech import analyse, to_dict

    deg = np.pi / 180
    analysis = analyse(pinmech.Scene.load(scenes_dir / "planar_arm.toml", ['solver.kernel="generated"']))
    links = to_dict(analysis)["links"]
    cramer = closed_form.planar_arm_rates(50 * deg, -15 * deg, -90 * deg, 0.3, 0.3, 0.17, np.array([1.0, 0.0]),
                                          np.zeros(2))
    np.testing.assert_allclose([links[n]["angular_velocity"][2] for n in ("AB", "BC")],
                               [cramer.omega_AB, cramer.omega_BC], rtol=1e-10)
    np.testing.assert_allclose([links[n]["angular_acceleration"][2] for n in ("AB", "BC")],
                               [cramer.alpha_AB, cramer.alpha_BC], rtol=1e-10)


def _swap_kind(model: pin.Model, j: int) -> None:
    """Joint `j` changed in place, with its indexes: a revolute about x, y or z becomes the
    prismatic along that axis, a prismatic the revolute, a continuous joint (nq 2) the prismatic."""
    was = model.joints[j]
    axis = was.shortname()[-1]
    other = {"R": "P", "P": "R", "U": "P"}[was.shortname()[len("JointModel")]]
    swapped = getattr(pin, f"JointModel{other}{axis}")()
    swapped.setIndexes(j, was.idx_q, was.idx_v, was.idx_vExtended)
    model.joints[j] = swapped


@needs_kernels
def test_a_joint_changed_in_place_never_runs_the_old_kernel(models_dir):
    """The slider-crank's slide changed in place from prismatic to revolute (same sizes, same
    tree): a core still holding the old kernel refuses to run it (a named ValueError), and the
    solver's next call runs a fresh kernel whose closure rows are Pinocchio's frame
    placements of the changed model (1e-15, as above)."""
    mech = pinmech.Mechanism.from_urdf(models_dir / "slider_crank.urdf")
    model, closure = mech.model, mech.closures[0]
    solver = LoopSolver(mech, ["O"], kernel="generated")
    compiled = core.core_for(solver)
    old = compiled.kernel_path
    assert old and not compiled.kernel_stale
    q = pin.integrate(model, pin.neutral(model), np.array([0.3, -0.2, 0.05]))
    _swap_kind(model, model.getJointId("slide"))
    assert compiled.kernel_stale
    with pytest.raises(ValueError, match="joints changed since its generated kernel"):
        compiled.residual(q)
    fresh = core.core_for(solver)
    assert fresh.kernel_path not in ("", old) and not fresh.kernel_stale
    np.testing.assert_allclose(fresh.errors6(q)[0, :3], _relative_position(model, closure, q), rtol=0, atol=1e-15)


@needs_kernels
def test_a_revolute_made_prismatic_in_place_is_refused_by_the_old_core(models_dir):
    """The four-bar's continuous rocker pivot (nq 2) made prismatic in place (nq 1; Pinocchio
    leaves the model's own nq as it was): the core holding the old kernel refuses every call,
    naming the change."""
    mech = pinmech.Mechanism.from_urdf(models_dir / "four_bar.urdf")
    compiled = core.core_for(LoopSolver(mech, ["O2"], kernel="generated"))
    q = pin.neutral(mech.model)
    _swap_kind(mech.model, mech.model.getJointId("O4"))
    with pytest.raises(ValueError, match="joints changed since its generated kernel"):
        compiled.residual(q)


@pytest.mark.parametrize("change", ["prismatic", "axis", "pitch", "mimic ratio"])
def test_the_kernel_key_covers_what_the_kernel_is_specialised_on(kernels_here, change):
    """A kernel is named by everything the generated code is specialised on: each change of
    a joint's type, axis, helical pitch or mimic ratio names another kernel; a changed joint
    placement (a dimension, an input of the kernel) names the same one."""
    def key(model):
        return kernel_build.kernel_key(kernel_build._structure(model))

    kind = {"prismatic": "translation", "axis": "prismatic_unaligned", "pitch": "helical", "mimic ratio": "mimic"}
    model, _ = _two_chains(kind[change])
    before = key(model)
    moved = model.copy()
    moved.jointPlacements[1] = pin.SE3(np.eye(3), np.array([0.3, 0.1, 0.0]))
    assert key(moved) == before
    changed = model.copy()
    j = 1
    if change == "prismatic":
        changed = pinmech.Mechanism.from_urdf(MODELS / "slider_crank.urdf").model
        before = key(changed)
        _swap_kind(changed, changed.getJointId("slide"))
    elif change == "axis":
        changed.joints[j] = _indexed(pin.JointModelPrismaticUnaligned(np.array([0.0, 0.6, 0.8])), model.joints[j])
    elif change == "pitch":
        changed.joints[j] = _indexed(pin.JointModelHelicalUnaligned(np.array([0.0, 0.0, 1.0]), 0.031), model.joints[j])
    else:
        changed.joints[3] = _indexed(pin.JointModelMimic(changed.joints[1], -1.25, 0.0), model.joints[3])
    assert key(changed) != before


def _indexed(joint, like):
    joint.setIndexes(like.id, like.idx_q, like.idx_v, like.idx_vExtended)
    return joint


def _build_slowly(out, counter):
    with open(counter, "a") as f:
        f.write("built\n")
    time.sleep(0.5)
    out.write_bytes(b"the same bytes")


def _ask(folder, counter, results):
    tempfile.tempdir = str(folder)
    from pinmech.user_cache import cached_build

    results.put(cached_build("thing", "0" * 64, "", lambda out: _build_slowly(out, counter))[1])


def test_processes_asking_at_once_build_a_cached_file_once(tmp_path):
    """Three processes ask the user cache for the same file at once (as `pytest -n` workers
    and a study's workers do): one builds it, the other two wait and find it built."""
    context = multiprocessing.get_context("fork")
    results = context.Queue()
    counter = tmp_path / "builds"
    workers = [context.Process(target=_ask, args=(tmp_path, counter, results)) for _ in range(3)]
    for w in workers:
        w.start()
    for w in workers:
        w.join(30)
    cached = sorted(results.get(timeout=5) for _ in workers)
    assert counter.read_text().count("built") == 1
    assert cached == [False, True, True]



@pytest.fixture
def counted_generations(monkeypatch):
    """Kernels made in this test: each kernel's name salted with the test's own word, so the
    first use generates one (whatever the cache holds) and every later one is counted."""
    made = []
    salted = kernel_build.kernel_key
    monkeypatch.setattr(kernel_build, "kernel_key", lambda text: salted(text + f"\0{os.getpid()}-{id(made)}"))
    real = kernel_build.make_kernel
    monkeypatch.setattr(kernel_build, "make_kernel", lambda *a, **k: made.append(1) or real(*a, **k))
    return made


@needs_kernels
@pytest.mark.parametrize("file, changes", [("four_bar_tolerance.toml", {"samples": 30, "batch": 10, "steps": 13}),
                                           ("four_bar_drawn_tolerance.toml", {"samples": 20, "batch": 10, "steps": 13}),
                                           ("four_bar_grid.toml", {"steps": 13}),
                                           ("five_bar_workspace.toml", {})])
def test_a_study_over_lengths_generates_one_kernel(models_dir, counted_generations, file, changes):
    """A tolerance study (of joint placements, and of a drawn linkage's lengths), a grid over
    lengths and a workspace grid with kernel="generated": the variants' lengths are the
    kernel's inputs, so the whole run makes one kernel."""
    import dataclasses

    from pinmech.design.study.run import load_any_study, study

    spec = dataclasses.replace(load_any_study(models_dir / "studies" / file), **changes)
    if spec.kind == "grid":
        spec = dataclasses.replace(spec, grid=tuple(dataclasses.replace(a, count=3) for a in spec.grid))
    if spec.kind == "workspace":
        spec = dataclasses.replace(spec, axes=tuple(dataclasses.replace(a, count=4) for a in spec.axes), refine_depth=0)
    study(spec, kernel="generated")
    assert len(counted_generations) == 1


@needs_kernels
def test_a_six_bar_synthesis_search_generates_one_kernel(models_dir, counted_generations):
    """A drawn six-bar's search with kernel="generated": every candidate's lengths are
    written into the one model, so the whole search makes one kernel."""
    import dataclasses

    from pinmech.design.synthesis.search import load_synthesis, synthesise

    spec = load_synthesis(models_dir / "synthesis" / "stephenson_function.toml")
    synthesise(dataclasses.replace(spec, generations=3, population=2, keep=1), kernel="generated")
    assert len(counted_generations) == 1


@needs_kernels
@pytest.mark.parametrize("poses, generator, expected", [(kernels.AUTO_POSES, True, "generated"),
                                                        (kernels.AUTO_POSES - 1, True, "generic"),
                                                        (kernels.AUTO_POSES, False, "generic")])
def test_auto_takes_the_kernel_for_a_long_run_where_the_generator_is_built(models_dir, monkeypatch, poses,
                                                                           generator, expected):
    """kernel = "auto" in a study's scene: the generated kernel for a run of AUTO_POSES poses
    or more where the generator is built here, the generic passes for a shorter run or where
    it is not (auto never starts the generator's one-time build)."""
    from pinmech.design.study.file import load_study
    from pinmech.design.study.variant import StudyMechanism

    if not generator:
        monkeypatch.setattr(kernel_build, "generator_built", lambda: False)
    import dataclasses

    spec = dataclasses.replace(load_study(models_dir / "studies" / "four_bar_tolerance.toml"), kernel="auto")
    sm = StudyMechanism(spec, poses=poses)
    assert sm.solver.kernel == expected
    assert bool(core.core_for(sm.solver).kernel_path) == (expected == "generated")


def test_auto_is_generic_for_one_sweep(models_dir):
    """A sweep's length is not known to the solver: "auto" there runs the generic passes."""
    mech = pinmech.Mechanism.from_urdf(models_dir / "four_bar.urdf")
    solver = LoopSolver(mech, ["O2"], kernel="auto")
    assert core.core_for(solver).kernel_path == ""


@pytest.mark.parametrize("env, said", [({"CC": "/nonexistent/cc"}, "no compiler found ($CC=/nonexistent/cc)"),
                                       ({"PATH": "", "CC": None, "CXX": "/nonexistent/c++"},
                                        "no compiler found (cc or gcc or clang)")])
def test_no_compiler_is_one_line_and_the_generic_passes(models_dir, monkeypatch, capsys, env, said):
    """CC naming no compiler, or PATH holding none (and CXX naming none): one line on stderr
    says so, the core keeps the generic passes, and "auto" never takes the kernel."""
    for name, value in env.items():
        if value is None:
            monkeypatch.delenv(name, raising=False)
        else:
            monkeypatch.setenv(name, value)
    monkeypatch.setattr(kernels, "_said", set())
    mech = pinmech.Mechanism.from_urdf(models_dir / "four_bar.urdf")
    compiled = core.compile_loops(mech.model, mech.closures, np.ones(mech.model.nv))[0]
    assert kernels.attach(compiled, mech.model, "generated") is None
    assert compiled.kernel_path == ""
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and said in err[0] and "generic" in err[0]
    assert kernels.resolved("auto", 10 ** 9) == "generic"


def _numbers(tree, out: dict, key: str = "") -> dict:
    """Every number of a nested dict / list (to_dict's), by its path."""
    if isinstance(tree, dict):
        for k, v in tree.items():
            _numbers(v, out, f"{key}.{k}")
    elif isinstance(tree, (list, tuple)):
        for i, v in enumerate(tree):
            _numbers(v, out, f"{key}[{i}]")
    elif isinstance(tree, (int, float)) and not isinstance(tree, bool):
        out[key] = float(tree)
    return out


@needs_kernels
@pytest.mark.parametrize("scene", SCENES)
def test_every_bundled_scene_answers_the_same_on_the_kernel(scenes_dir, scene, monkeypatch):
    """Every bundled scene's analysis (pose, rates, forces where asked) with kernel = "generated":
    the kernel runs, and every number equals the generic one to 1e-13 of its size (the
    module's docstring derives the bound; a Newton solve on either stops within its tolerance
    of the same root, so the poses agree to rounding too)."""
    from pinmech import analyse, to_dict

    ran = []
    attach = kernels.attach
    monkeypatch.setattr(kernels, "attach", lambda *a: ran.append(attach(*a)) or ran[-1])
    try:
        generic = _numbers(to_dict(analyse(pinmech.Scene.load(scenes_dir / scene))), {})
    except ImportError as missing:  # the robots' scenes need pinmech[robots]
        pytest.skip(str(missing))
    generated = _numbers(to_dict(analyse(pinmech.Scene.load(scenes_dir / scene, ['solver.kernel="generated"']))), {})
    assert any(ran), "the kernel did not run"
    assert generated.keys() == generic.keys()
    for key, a in generic.items():
        if np.isfinite(a):
            assert abs(generated[key] - a) <= 1e-13 * max(1.0, abs(a)), key
