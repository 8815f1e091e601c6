"""The laying orders of construction stages (docs/model.md 4.7), by name: what
:mod:`masonry.stages.analysis` lays and what the command line offers, without loading the
study."""

BRICK_ORDERS = {
    "pattern-first": "the pattern bricks that start on the course, from one corner to "
                     "the other; then the regular and fill-in bricks, nearest to a pattern "
                     "brick first (each next to one already laid), ties from one corner",
    "along": "every brick of the course by its position along the course, from the "
             "corner at -pi/n to the corner at +pi/n",
}
"""Laying orders of :func:`~masonry.stages.plans.brick_plan` (docs/model.md 4.7)."""

BLOCK_ORDERS = {
    "names": "one block at a time, by name (digits compared as numbers)",
    "z": "from the bottom up by centroid height; blocks at one height together",
}
"""Laying orders of :func:`~masonry.stages.plans.block_plan`."""
