"""masonry: double-helix masonry domes brick by brick, their contact interfaces, rigid
block equilibrium (RBE), collapse load and construction stages.

The Python interface (:mod:`masonry.api`)::

    import masonry
    dome = masonry.build(preset="3", scene="dome")  # all 4 webs: a cyclic section refuses
                                                    # a lateral load
    dome.solve().verdict, dome.forces(), dome.collapse(lateral=0), dome.export()

The package reads as the pipeline, one stage per module or folder::

    params -> dome (levels, pattern, courses) -> scenes (blocks) -> interfaces
           -> rbe (equilibrium, solve, collapse) -> printable, plots -> export
           -> pipeline (the run) -> studies -> api
"""

__version__ = "0.1.0"

_API = ("build", "read", "read_table", "Structure")


def __getattr__(name):
    # the interface imports the whole pipeline: ``import masonry`` alone stays light
    if name in _API:
        from masonry import api

        return getattr(api, name)
    raise AttributeError(f"module 'masonry' has no attribute {name!r}")


def __dir__():
    return sorted([*globals(), *_API])
