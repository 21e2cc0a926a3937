"""References to code in campaign files: `package.module:name` (importable) or `file.py:name` (a file beside the
campaign file, for users whose PLC logic or check is not a package)."""
from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path


class LoadError(ValueError):
    """A reference that does not lead to an object: says which part failed."""


def load_object(ref: str, base: Path):
    module_ref, _, attr = ref.rpartition(":")
    if not module_ref or not attr:
        raise LoadError(f"{ref!r} is not \"module:name\" or \"file.py:name\"")
    if module_ref.endswith(".py"):
        path = (base / module_ref).resolve()
        if not path.is_file():
            raise LoadError(f"{ref!r}: no file {path}")
        name = f"campaign_code_{abs(hash(str(path)))}"
        module = sys.modules.get(name)
        if module is None:
            spec = importlib.util.spec_from_file_location(name, path)
            module = importlib.util.module_from_spec(spec)
            sys.modules[name] = module
            try:
                spec.loader.exec_module(module)
            except Exception as exc:
                del sys.modules[name]
                raise LoadError(f"{ref!r}: {path.name} fails to load: {type(exc).__name__}: {exc}") from None
    else:
        try:
            module = importlib.import_module(module_ref)
        except ImportError as exc:
            raise LoadError(f"{ref!r}: cannot import {module_ref!r}: {exc}") from None
    try:
        obj = module
        for part in attr.split("."):
            obj = getattr(obj, part)
    except AttributeError:
        raise LoadError(f"{ref!r}: {module_ref} has no {attr!r}") from None
    return obj
