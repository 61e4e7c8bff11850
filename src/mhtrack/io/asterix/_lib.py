"""The ASTERIX codec: libasterix (PyPI ``libasterix``, MIT, pure Python; module
``asterix``), an optional extra. Every bit of CAT048/CAT034 is encoded and decoded by it;
mhtrack only frames data blocks (category, length) and reads the items it needs.

Editions: CAT048 1.32 and CAT034 1.29, the newest that libasterix carries; the items
mhtrack reads (I048/010, 020, 040, 070, 090, 140, 161, 220, 240; I034/000, 010, 020, 030,
041) have kept their layout across the editions in use (CAT048 since 1.15).
"""

from __future__ import annotations

from functools import cache
from types import ModuleType
from typing import Any

#: The line shown when libasterix is missing.
INSTALL_HINT = ("ASTERIX needs the optional package libasterix: pip install "
                "'mhtrack[asterix]'")


class MissingExtra(ModuleNotFoundError):
    """libasterix is not installed (the message names ``pip install 'mhtrack[asterix]'``)."""


@cache
def modules() -> tuple[ModuleType, ModuleType]:
    """``(asterix.base, asterix.generated)``, or :class:`MissingExtra`."""
    try:
        import asterix.base as base
        import asterix.generated as gen
    except ImportError:
        raise MissingExtra(INSTALL_HINT) from None
    if not hasattr(gen, "Cat_048_1_32"):  # another package named 'asterix'
        raise MissingExtra(INSTALL_HINT + " (the installed 'asterix' module is not "
                           "libasterix)")
    return base, gen


def cat048() -> Any:
    """libasterix's CAT048 edition 1.32."""
    return modules()[1].Cat_048_1_32


def cat034() -> Any:
    """libasterix's CAT034 edition 1.29."""
    return modules()[1].Cat_034_1_29


def cat062() -> Any:
    """libasterix's CAT062 edition 1.18 (the edition most system trackers send)."""
    return modules()[1].Cat_062_1_18


def version() -> str:
    """The installed libasterix version."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as dist_version

    modules()
    try:
        return dist_version("libasterix")
    except PackageNotFoundError:
        return "unknown"


# --- item access shared by the category readers (libasterix's parsed records) ----------

def quantity(item: Any, unit: str) -> float:
    """An item's content as a physical quantity in ``unit`` (libasterix ``as_quantity``)."""
    return float(item.variation.content.as_quantity(unit))


def uint(item: Any) -> int:
    """An item's content as an unsigned integer."""
    return int(item.variation.content.as_uint())


def sub_or_none(item: Any, name: str) -> Any:
    """Subitem ``name`` of a compound or group item, or ``None`` where it is absent."""
    try:
        return item.variation.get_item(name)
    except (KeyError, ValueError):
        return None
