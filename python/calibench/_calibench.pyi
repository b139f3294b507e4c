# Type stubs of the extension module (python/module.cpp); the package `calibench` wraps it.
from typing import Callable, Optional

version: str

def run(
    args: list[str], progress: Optional[Callable[[str, int, int, str], None]] = None
) -> tuple[int, bytes, bytes]:
    """Runs `calibench *args` in-process with the GIL released: (exit code, stdout, stderr)."""

def commands() -> list[str]:
    """The subcommands' names."""
