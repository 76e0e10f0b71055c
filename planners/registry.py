"""The planner registry: ``PLANNERS`` maps a registry name (the YAML ``planners[i].name``) to its class.

The package's face (:mod:`planners`) fills it with the planners slewbench ships; a user's planner is
added with ``PLANNERS[MyPlanner.name] = MyPlanner`` (:doc:`/extending/planner`). Planners that plan
from other planners' references (``collocation``'s warm starts and seeds) look them up here: the
registry is complete by the time any planner runs, because importing any module of
:mod:`planners` imports the package, and so its face, first.

An unknown name raises :class:`~planners.errors.UnknownNameError` (a ``KeyError``) that lists the
registered names, as the YAML loader does; :class:`Registry` is that dictionary, which
``controllers.CONTROLLERS`` uses too.

May import: :mod:`planners.base` (for the type) and :mod:`planners.errors`; nothing else of slewbench.
"""
from __future__ import annotations

from typing import TypeVar

from planners.base import Planner
from planners.errors import UnknownNameError

__all__ = ["PLANNERS", "Registry"]

V = TypeVar("V")


class Registry(dict[str, V]):
    """A dictionary of registry names to classes whose unknown names raise
    :class:`~planners.errors.UnknownNameError` listing the registered ones.

    Parameters
    ----------
    kind : str
        What it holds (``"planner"``), for the message; kept as :attr:`kind`.
    *args, **kwargs
        The entries, as for ``dict``.
    """

    def __init__(self, kind: str, *args: object, **kwargs: V) -> None:
        super().__init__(*args, **kwargs)
        self.kind = kind

    def __missing__(self, name: str) -> V:
        """Raise :class:`~planners.errors.UnknownNameError` (``registry[name]`` of an unknown name).

        Parameters
        ----------
        name : str
            The name looked up.

        Returns
        -------
        NoReturn
            Never: it raises.
        """
        raise UnknownNameError(self.kind, name, self)


PLANNERS: Registry[type[Planner]] = Registry("planner")
"""Registry name -> planner class."""
