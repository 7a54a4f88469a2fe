"""pkm._derived: what a layer above a class derives from an instance, made once and kept with it."""

from __future__ import annotations

from pkm._derived import SLOT, derived


class _Owner:
    pass


def test_made_once_per_owner_and_maker_and_kept_in_the_owner():
    """The second call gives the same object without calling the maker; another maker or another owner makes its
    own; dropping the slot (as a mechanism does when its reference changes) makes it again."""
    calls: list[object] = []

    def make(owner):
        calls.append(owner)
        return [len(calls)]

    a, b = _Owner(), _Owner()
    first = derived(a, make)
    assert derived(a, make) is first and calls == [a]
    assert derived(b, make) is not first and calls == [a, b]
    assert derived(a, type) is _Owner and calls == [a, b]  # (another maker, kept apart)
    assert a.__dict__[SLOT] == {make: first, type: _Owner}
    del a.__dict__[SLOT]
    assert derived(a, make) == [3]
