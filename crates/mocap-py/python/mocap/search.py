"""Motion retrieval by example (``mocap search``): a random forest over
relative pose features classifies a clip and ranks a library's clips.

>>> index = mocap.search.Index.load("library.idx")   # or Index.bundled()
>>> result = index.query(m, top=10)
>>> result.label, result.probability, result.matches[0].path
"""

from ._mocap import Index, Match, QueryResult

__all__ = ["Index", "Match", "QueryResult"]
