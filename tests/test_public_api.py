"""Every name the package promises in ``slamtrials.__all__`` resolves."""

from __future__ import annotations

import pytest

import slamtrials


@pytest.mark.parametrize("name", slamtrials.__all__)
def test_public_name_resolves(name):
    assert getattr(slamtrials, name) is not None


def test_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError):
        slamtrials.no_such_thing  # noqa: B018
