"""The double-helix model of one web, in the flattened section: the level table of the
intrados (:mod:`.levels`), the pattern lines of pattern bricks (:mod:`.pattern`) and the
courses of regular and fill-in bricks between them (:mod:`.courses`). Units, not solids:
:mod:`masonry.scenes` poses the bricks."""
