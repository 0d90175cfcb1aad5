"""Generated kernels, built: Pinocchio's kinematic passes specialised to one model, as C,
compiled by the system compiler and kept in the user's private cache (user_cache.py).

Two builds, each cached under the SHA-256 of everything it is made from:

  * the generator (pinmech/kernelgen/generator.cpp), once per machine and versions: it
    needs a C++17 compiler, the Pinocchio headers of the installed `pin` and the headers of
    the `pinmech[fast]` extra (CppAD, CppADCodeGen, Eigen); about 1-3 minutes and 2.8 GB;
  * a model's kernel: the generator tapes the model (its joints and tree; the joint
    placements stay inputs, so a changed dimension uses the same kernel) and writes C,
    which the C compiler makes a shared library (a second or two).

Where a piece is missing, `KernelUnavailable` says which in one line (kernels.py prints it
and the generic passes run).
"""

from __future__ import annotations

import functools
import hashlib
import os
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from importlib import metadata, resources
from pathlib import Path

import pinocchio as pin

from pinmech.user_cache import cached_build, cached_path

#: Versions that go into the generator's build (its cache key).
_VERSIONED = ("libpinocchio", "cmeel-boost", "cmeel-eigen", "cmeel-cppad", "cmeel-cppadcodegen")
#: Pinocchio's compile definitions (pinocchioTargets.cmake: pinocchio_headers, pinocchio_default).
_DEFINITIONS = ("BOOST_MPL_LIMIT_LIST_SIZE=30", "BOOST_MPL_LIMIT_VECTOR_SIZE=30", "BOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
                "BOOST_FUSION_INVOKE_MAX_ARITY=12", "PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION")
#: The kernel's C flags: no contraction into fused multiply-adds and no reassociation, so
#: each output is the generic pass's sum of products, rounded as the generated order has it.
KERNEL_FLAGS = ("-O2", "-fPIC", "-shared", "-ffp-contract=off", "-fno-math-errno")


class KernelUnavailable(Exception):
    """A generated kernel cannot be built here (no compiler, no `pinmech[fast]`...): the message says which."""


@dataclass(frozen=True)
class KernelBuild:
    """A model's kernel: its shared library, and what making it cost.

    Attributes:
        path: the shared library in the user's cache.
        cached: it was there already (nothing generated or compiled now).
        generate_seconds, compile_seconds: time to write the C and to compile it [s] (0 where cached).
        bytes: the library's size; c_bytes: the C source's (0 where cached).
    """

    path: Path
    cached: bool
    generate_seconds: float = 0.0
    compile_seconds: float = 0.0
    bytes: int = 0
    c_bytes: int = 0


def build_kernel(model: pin.Model) -> KernelBuild:
    """The kernel of `model`'s joints and tree, from the cache or generated and compiled now."""
    text = _structure(model)
    key = kernel_key(text)
    cc = _compiler("CC", ("cc", "gcc", "clang"))
    made: list[tuple[float, float, int, int]] = []
    path, cached = cached_build("kernel", key, ".so", lambda out: made.append(make_kernel(model, out, text, cc)))
    generate, compile_, c_bytes, _ = made[0] if made else (0.0, 0.0, 0, 0)
    return KernelBuild(path, cached, generate, compile_, path.stat().st_size, c_bytes)


def kernel_key(text: str) -> str:
    """The SHA-256 of everything a kernel is made from: the model's structure (`text`: its
    joints with their types, axes, pitches and mimic ratios, its tree and frames), the C
    compiler, its version and flags, and the generator's own key (generator.cpp, the
    Pinocchio, Boost, Eigen and CppAD versions, the C++ compiler and its version)."""
    cc = _compiler("CC", ("cc", "gcc", "clang"))
    return hashlib.sha256("\0".join([text, cc, _compiler_version(cc), " ".join(KERNEL_FLAGS),
                                     generator_recipe()[3]]).encode()).hexdigest()


def make_kernel(model: pin.Model, out: Path, text: str | None = None,
                cc: str | None = None) -> tuple[float, float, int, int]:
    """Generate `model`'s kernel as C and compile it to `out` (no cache); returns the
    seconds to write the C, the seconds to compile it, the C's and the library's sizes [bytes]."""
    text = _structure(model) if text is None else text
    cc = cc or _compiler("CC", ("cc", "gcc", "clang"))
    generator = generator_path()
    temporary_model, c_file = out.with_suffix(".model"), out.with_suffix(".c")  # beside the cache's temporary
    try:
        temporary_model.write_text(text)
        start = time.perf_counter()
        _run([str(generator), str(temporary_model), str(c_file)], "the kernel generator")
        generate = time.perf_counter() - start
        c_bytes = c_file.stat().st_size
        start = time.perf_counter()
        _run([cc, *KERNEL_FLAGS, "-o", str(out), str(c_file)], "the C compiler")
        return generate, time.perf_counter() - start, c_bytes, out.stat().st_size
    finally:
        for leftover in (temporary_model, c_file):
            leftover.unlink(missing_ok=True)


def generator_path() -> Path:
    """The compiled kernel generator (built once, with a line on stderr saying so)."""
    cxx, include, libdir, key = generator_recipe()

    def make(out: Path) -> None:
        print("pinmech: building the kernel generator (once for this machine; 1-3 minutes)", file=sys.stderr)
        source = Path(str(resources.files("pinmech") / "kernelgen" / "generator.cpp"))
        flags = ["-std=c++17", "-O1", *(f"-D{d}" for d in _DEFINITIONS)]
        flags += [arg for d in include for arg in ("-isystem", d)]
        libs = ["-L" + libdir, "-Wl,-rpath," + libdir, "-lpinocchio_default", "-lboost_serialization", "-lcppad_lib"]
        _run([cxx, *flags, str(source), "-o", str(out), *libs], "the C++ compiler (building the kernel generator)")

    return cached_build("kernelgen", key, "", make)[0]


def generator_built() -> bool:
    """The kernel generator is built for this machine and versions already, and the C compiler
    a kernel needs is here (nothing is built now)."""
    try:
        _compiler("CC", ("cc", "gcc", "clang"))
        key = generator_recipe()[3]
    except KernelUnavailable:
        return False
    return cached_path("kernelgen", key, "") is not None


def generator_recipe() -> tuple[str, list[str], str, str]:
    """The C++ compiler, include folders and library folder the generator is built with,
    and its cache key (the SHA-256 of them, of the versions and of generator.cpp)."""
    cxx = _compiler("CXX", ("c++", "g++", "clang++"))
    prefixes = _cmeel_prefixes()
    include = _include_dirs(prefixes)
    libdir = _library_dir(prefixes)
    versions = ";".join(f"{name}={_version(name)}" for name in _VERSIONED)
    key = hashlib.sha256("\0".join([_generator_source(), versions, cxx, _compiler_version(cxx), *include,
                                    libdir]).encode()).hexdigest()
    return cxx, include, libdir, key


def _structure(model: pin.Model) -> str:
    """The model as the generator reads it, with what a kernel does not depend on set to
    fixed values (joint and frame placements, inertias): one kernel serves every dimension."""
    shape = model.copy()
    for j in range(1, shape.njoints):
        shape.jointPlacements[j] = pin.SE3.Identity()
        shape.inertias[j] = pin.Inertia.Zero()
    for frame in shape.frames:
        frame.placement = pin.SE3.Identity()
        frame.inertia = pin.Inertia.Zero()
    return shape.saveToString()


def _run(command: list[str], what: str) -> None:
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        lines = (done.stderr or done.stdout).strip().splitlines()
        raise KernelUnavailable(f"{what} failed ({lines[-1] if lines else f'exit {done.returncode}'})")


def _compiler(variable: str, names: tuple[str, ...]) -> str:
    """$CC or $CXX where set, else the first of `names` on PATH, as a full path."""
    asked = os.environ.get(variable)
    for name in ([asked] if asked else names):
        found = shutil.which(name)
        if found:
            return found
    said = f"${variable}={asked}" if asked else " or ".join(names)
    raise KernelUnavailable(f"no compiler found ({said}); generated kernels need one at run time")


@functools.lru_cache(maxsize=8)
def _compiler_version(path: str) -> str:
    done = subprocess.run([path, "--version"], capture_output=True, text=True)
    return done.stdout.splitlines()[0] if done.returncode == 0 and done.stdout else path


def _cmeel_prefixes() -> list[Path]:
    return [p for p in (Path(s) / "cmeel.prefix" for s in sys.path if s) if p.is_dir()]


def _include_dirs(prefixes: list[Path]) -> list[str]:
    """Where the Pinocchio, Eigen, Boost and CppAD(CG) headers are, or KernelUnavailable."""
    wanted = {"pinocchio/codegen/cppadcg.hpp": "", "Eigen/Core": "eigen3", "boost/version.hpp": "",
              "cppad/cg.hpp": ""}
    found = []
    for header, sub in wanted.items():
        where = next((p / "include" / sub for p in prefixes if (p / "include" / sub / header).is_file()), None)
        if where is None:
            raise KernelUnavailable(f"no {header} found; generated kernels need `pip install pinmech[fast]`")
        found.append(str(where))
    return sorted(set(found))


def _library_dir(prefixes: list[Path]) -> str:
    for p in prefixes:
        if (p / "lib" / "libpinocchio_default.so").is_file():
            return str(p / "lib")
    raise KernelUnavailable("no libpinocchio_default.so found beside the installed pin")


def _version(name: str) -> str:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return "absent"


def _generator_source() -> str:
    return (resources.files("pinmech") / "kernelgen" / "generator.cpp").read_text()


def describe(build: KernelBuild) -> str:
    """One line: where the kernel is, and what it cost (or that it was cached)."""
    if build.cached:
        return f"generated kernel {build.path.name} ({build.bytes / 1024:.0f} kB, cached)"
    return (f"generated kernel {build.path.name}: C written in {build.generate_seconds:.2f} s "
            f"({build.c_bytes / 1024:.0f} kB), compiled in {build.compile_seconds:.2f} s ({build.bytes / 1024:.0f} kB)")
