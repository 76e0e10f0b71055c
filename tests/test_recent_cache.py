"""ocp.cache.RecentCache: the most recently used entries, per thread, up to its size; pickled or
deep-copied, a new empty cache of the same size."""
from __future__ import annotations

import copy
import pickle
import threading

from ocp.cache import RecentCache


def test_the_least_recently_used_entry_goes_first():
    cache = RecentCache(size=2)
    built = []
    for key in "abacab":  # a's hit makes b the least recent: c evicts b, not a; b is built again, evicting c
        cache.get(key, lambda key=key: built.append(key) or key)
    assert built == ["a", "b", "c", "b"] and cache.hits == 2 and cache.builds == 4 and len(cache) == 2
    assert cache.get("a", lambda: "built") == "a" and cache.hits == 3


def test_each_thread_keeps_its_own_entries_up_to_the_size():
    """A thread never gets another thread's entry, and each thread's entries are bounded on their own."""
    cache = RecentCache(size=3)
    mine = [cache.get(k, object) for k in range(5)]
    theirs: list[object] = []
    thread = threading.Thread(target=lambda: theirs.extend(cache.get(k, object) for k in range(5)))
    thread.start()
    thread.join()
    assert not {id(v) for v in mine} & {id(v) for v in theirs}
    assert cache.builds == 10 and cache.get(4, object) is mine[4]
    assert len(cache) == 3  # the other thread's entries went with it


def test_a_copy_is_empty_and_keeps_the_size():
    cache = RecentCache(size=5)
    for k in range(3):
        cache.get(k, object)
    for again in (pickle.loads(pickle.dumps(cache)), copy.deepcopy(cache)):
        assert isinstance(again, RecentCache) and len(again) == 0 and again.size == 5
        for k in range(8):
            again.get(k, object)
        assert len(again) == 5
