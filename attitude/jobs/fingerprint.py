"""What a process runs: a digest of the package's code and the versions of the
libraries its numbers depend on, to tell a worker that runs other code from one that
runs this code (:func:`attitude.jobs.cluster.check_workers`) and to tie a job's
checkpoint to the code that wrote it (:mod:`attitude.jobs.checkpoint`).

The version string alone does not tell them apart: a worker running edited code (a
fix tried on one machine of the cluster, a stale checkout) under the same version
gave samples 1 % off.  The digest is SHA-256 over every ``.py`` file of the package
(its path inside the package and its bytes, in path order): 150-odd files, about
3 MB, read once per process (a few ms).
"""

from __future__ import annotations

import functools
import hashlib
from importlib import metadata
from pathlib import Path

from attitude.base.version import __version__

__all__ = ["code_digest", "differences", "what_runs"]

_PACKAGE = Path(__file__).resolve().parents[1]

# The libraries whose results a job's numbers depend on, beside the package itself.
_LIBRARIES = ("numpy", "scipy", "numba")


@functools.cache
def code_digest() -> str:
    """SHA-256 (hex) of the package's ``.py`` files, their paths and bytes."""
    sha = hashlib.sha256()
    for path in sorted(_PACKAGE.rglob("*.py")):
        sha.update(path.relative_to(_PACKAGE).as_posix().encode())
        sha.update(b"\0")
        sha.update(path.read_bytes())
        sha.update(b"\0")
    return sha.hexdigest()


def _library_version(name: str) -> str:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return "absent"


@functools.cache
def what_runs() -> dict[str, str]:
    """The package's version and code digest, and the libraries' versions, in this
    process (a worker answers the same call)."""
    return {
        "attitude": __version__,
        "code": code_digest(),
        **{name: _library_version(name) for name in _LIBRARIES},
    }


def differences(theirs: dict[str, str], here: dict[str, str]) -> list[str]:
    """What differs between ``theirs`` (a worker's :func:`what_runs`) and ``here``, in
    words ("numpy 2.3.0 where this process runs 2.4.6")."""
    said = []
    if theirs.get("attitude") != here["attitude"]:
        said.append(f"attitude {theirs.get('attitude')} where this process runs {here['attitude']}")
    elif theirs.get("code") != here["code"]:
        said.append(
            f"other code under the same version {here['attitude']} (the digest of its .py "
            f"files {str(theirs.get('code'))[:12]} where this process has {here['code'][:12]})"
        )
    for name in _LIBRARIES:
        if theirs.get(name) != here[name]:
            said.append(f"{name} {theirs.get(name)} where this process runs {here[name]}")
    return said
