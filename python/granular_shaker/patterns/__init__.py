"""The onset-of-patterns study (docs/patterns.md): fits of the onset acceleration to an order
parameter measured against Gamma, or the continuum's growth rate."""
from .growth import (GrowthBand, GrowthRate, NoGrowthFit, ZeroCrossing, column_mass_modes,
                     fastest_pattern_mode, fit_growth_rate, fit_zero_crossing, growth_bands)
from .onset import NoOnset, OnsetFit, SwiftHohenbergFit, fit_onset, fit_swift_hohenberg

__all__ = ["GrowthBand", "GrowthRate", "NoGrowthFit", "NoOnset", "OnsetFit", "SwiftHohenbergFit",
           "ZeroCrossing", "column_mass_modes", "fastest_pattern_mode", "fit_growth_rate",
           "fit_onset", "fit_swift_hohenberg", "fit_zero_crossing", "growth_bands"]
