"""The one place where the package's whole-number and real arguments are
checked before they reach the compiled core: a bad value raises
``TypeError`` (not a number of the right kind) or ``ValueError`` (out of
range), naming the argument, the value and what is accepted. The core
checks the rules of the testbed itself (an accuracy in (0.5, 1), a
scenario's fields), naming the argument too.
"""

from __future__ import annotations

import math
import numbers
import os
from typing import Optional

#: The largest seed: what a scenario file (TOML, a signed 64-bit integer)
#: can hold, as ``errp run --seed`` accepts.
MAX_SEED = 2**63 - 1


def whole(name: str, value, lo: int, hi: int, *, optional: bool = False) -> Optional[int]:
    """``value`` as an ``int`` in ``[lo, hi]`` (``None`` passes if
    ``optional``). Python and NumPy integers are accepted; ``bool``, floats
    and strings are not, as in scikit-learn."""
    expected = f"a whole number from {lo} to {hi}"
    if value is None:
        if optional:
            return None
        raise TypeError(f"{name} must be {expected}, not None")
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be {expected}, not {type(value).__name__} {value!r}")
    v = int(value)
    if not lo <= v <= hi:
        raise ValueError(f"{name} = {v} is invalid: expected {expected}")
    return v


def seed(name: str, value, *, optional: bool = False) -> Optional[int]:
    """A seed: a whole number from 0 to 2^63 - 1."""
    return whole(name, value, 0, MAX_SEED, optional=optional)


def real(
    name: str, value, *, optional: bool = False, what: str = "a finite number"
) -> Optional[float]:
    """``value`` as a finite ``float`` (``None`` passes if ``optional``);
    ``bool`` and strings are refused. Its range is the core's to check
    (``what`` only words the messages)."""
    if value is None:
        if optional:
            return None
        raise TypeError(f"{name} must be {what}, not None")
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be {what}, not {type(value).__name__} {value!r}")
    try:
        v = float(value)
    except OverflowError:
        # An integer too large for a float (10**400).
        size = int(int(value).bit_length() * math.log10(2))
        raise ValueError(
            f"{name} = an integer of about 10^{size} is invalid: it is too large for a float; "
            f"expected {what}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} = {v!r} is invalid: expected {what}")
    return v


def accuracy(
    name: str, value, *, optional: bool = False, oracle: bool = True
) -> Optional[float]:
    """A decoder's mean accuracy: the core checks its range, (0.5, 1) or 1
    for the oracle (``oracle``), as ``errp run --accuracy`` does; here its
    type and that it is finite."""
    what = ("a mean accuracy in (0.5, 1), or 1 for the oracle" if oracle
            else "a mean accuracy strictly between 0.5 and 1")
    return real(name, value, optional=optional, what=what)


def path(name: str, value) -> Optional[str]:
    """A file or directory path: a ``str`` or an ``os.PathLike`` of one
    (``None`` passes). Bytes are refused, naming the argument (a name that
    is not UTF-8 is given as ``os.fsdecode(raw)``)."""
    if value is None:
        return None
    try:
        v = os.fspath(value)
    except TypeError:
        raise TypeError(
            f"{name} must be a path (str or os.PathLike), not {type(value).__name__} {value!r}"
        ) from None
    if isinstance(v, bytes):
        raise TypeError(
            f"{name} must be a path as str, not bytes {value!r} (use os.fsdecode for a raw name)"
        )
    return v
