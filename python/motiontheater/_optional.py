"""Optional dependencies: imported where they are needed, with one line naming the extra to install."""

from __future__ import annotations

import importlib
from types import ModuleType


class MissingExtraError(ImportError, RuntimeError):
    """An optional dependency is not installed; the message says which extra brings it.
    (A RuntimeError too, so that the command line reports it as one line.)"""


def require(module: str, extra: str, purpose: str) -> ModuleType:
    """``import module``, or MissingExtraError: "<purpose> needs <package>: pip install 'motiontheater[extra]'"."""
    try:
        return importlib.import_module(module)
    except ImportError:
        package = module.split(".")[0]
        raise MissingExtraError(f"{purpose} needs {package}: pip install 'motiontheater[{extra}]'") from None
