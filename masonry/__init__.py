"""masonry: double-helix masonry domes brick by brick, their contact interfaces and
rigid block equilibrium (RBE).

Pipeline, one module per stage::

    params -> levels -> pattern -> courses -> scenes/blocks -> interfaces
           -> equilibrium (matrices) -> solve -> results -> exports / plots
"""

__version__ = "0.1.0"
