"""Scenes: what one run models, as :class:`~masonry.blocks.Blocks` (SPEC 4.6).

- ``section``: one web of the dome, facing +x, on a ground slab (:mod:`.section`).
- ``dome``: all ``n`` webs explicitly (:mod:`.section`).
- ``wall``: a straight running-bond wall on a ground slab, for validation (:mod:`.wall`).
- ``arch``: voussoirs on two supports (:mod:`.arch`).
- ``assembly``: blocks read from mesh files (:mod:`.imported`, built by
  :func:`~masonry.scenes.imported.load_assembly`, not from parameters alone).

:class:`~masonry.scenes.base.Scene` is what every builder returns.
"""

from masonry.params import Params
from masonry.scenes.arch import build_arch
from masonry.scenes.base import Scene
from masonry.scenes.section import build_dome, build_section
from masonry.scenes.wall import build_wall

BUILDERS = {"section": build_section, "wall": build_wall, "dome": build_dome,
            "arch": build_arch}
"""Scene name -> builder of a :class:`Scene` from :class:`~masonry.params.Params`."""


def build(params: Params) -> Scene:
    """The scene ``params.scene`` asks for."""
    try:
        builder = BUILDERS[params.scene]
    except KeyError:
        raise NotImplementedError(f"scene {params.scene!r} is not built from parameters "
                                  "alone") from None
    return builder(params)
