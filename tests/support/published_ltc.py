"""Where the tests find the published LTC tables (:mod:`pbrkit.ltc.published`): the
pinned npm three of ``tests/engines`` (``npm ci --prefix tests/engines``, as
``.ci/run`` does).  The library never looks there; tests and benchmarks pass the path."""

from pathlib import Path

#: three's npm package of the pinned engines.
THREE = Path(__file__).resolve().parents[1] / "engines" / "node_modules" / "three"


def three_missing():
    """Why the published tables cannot be read here, or None."""
    from pbrkit.ltc.published import published_table_path

    try:
        published_table_path(THREE)
    except FileNotFoundError:
        return ("needs three's npm package (tests/engines/node_modules/three, npm ci --prefix tests/engines) "
                "for the published LTC tables")
    return None


#: The skip reason of tests that read the published tables (None where they can run).
THREE_REASON = three_missing()
