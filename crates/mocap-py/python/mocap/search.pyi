from ._mocap import Index as Index
from ._mocap import Match as Match
from ._mocap import QueryResult as QueryResult

__all__ = ["Index", "Match", "QueryResult"]
