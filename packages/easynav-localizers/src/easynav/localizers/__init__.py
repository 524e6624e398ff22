"""EasyNav localizers: the simple AMCL particle filter.

The algorithm (:class:`ParticleFilter2D`, :func:`hit_fractions`) is plain numpy; the plugin
(``easynav.localizers.amcl_localizer``) is not imported here.
"""

from easynav.localizers.particle_filter import (
    ParticleFilter2D,
    hit_fractions,
    likelihood_field,
    surface_cells,
)

__all__ = ["ParticleFilter2D", "hit_fractions", "likelihood_field", "surface_cells"]
