"""ocp.cache.exact_key on enum members: a member is keyed by its type and its value, so that an
``IntEnum`` or ``StrEnum`` member (which *is* an int or a str, and compares equal to one) never
makes the key of the plain value it equals, nor of another enum's member of the same value; and a
cache keyed by them keeps them apart.

Oracles: Python's own equality and type identity (the members are built by hand here).
"""
from __future__ import annotations

import enum

from ocp.cache import SolverCache, exact_key


class Level(enum.IntEnum):
    LOW = 1
    HIGH = 2


class Other(enum.IntEnum):
    LOW = 1


class Mode(enum.StrEnum):
    FAST = "fast"


class Colour(enum.Enum):
    RED = object()  # a value exact_key cannot state: the member's name keys it
    BLUE = object()


class Bits(enum.IntFlag):
    A = 1
    B = 2


def test_an_int_enum_member_is_not_the_int_it_equals():
    assert Level.LOW == 1 and isinstance(Level.LOW, int)  # Python's equality would merge them: the key must not
    assert exact_key(Level.LOW) != exact_key(1)
    assert exact_key({"level": Level.LOW}) != exact_key({"level": 1})
    assert exact_key(Level.LOW) != exact_key(Other.LOW)  # same value, another type
    assert exact_key(Level.LOW) != exact_key(Level.HIGH)
    assert exact_key(Level.LOW) == exact_key(Level(1))


def test_a_str_enum_member_is_not_the_str_it_equals():
    assert Mode.FAST == "fast" and isinstance(Mode.FAST, str)
    assert exact_key(Mode.FAST) != exact_key("fast")
    assert exact_key([Mode.FAST]) != exact_key(["fast"])
    assert exact_key(Mode.FAST) == exact_key(Mode("fast"))


def test_members_of_values_without_an_exact_key_and_unnamed_flags_stay_apart():
    assert exact_key(Colour.RED) != exact_key(Colour.BLUE)
    assert exact_key(Colour.RED) == exact_key(Colour["RED"])
    assert Bits(0).name is None and Bits(4).name is None  # unnamed: their values tell them apart
    assert exact_key(Bits(0)) != exact_key(Bits(4))
    assert exact_key(Bits.A | Bits.B) == exact_key(Bits(3)) != exact_key(3)


def test_a_cache_keyed_by_a_member_and_its_int_builds_both():
    cache = SolverCache()
    built = [cache.get(exact_key(key), lambda key=key: repr(key)) for key in (Level.LOW, 1, Other.LOW)]
    assert built == [repr(Level.LOW), "1", repr(Other.LOW)]
    assert cache.builds == 3 and cache.hits == 0
