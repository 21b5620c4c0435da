"""The onset-of-patterns study (docs/patterns.md): fits of the onset acceleration to an order
parameter measured against Gamma."""
from .onset import NoOnset, OnsetFit, SwiftHohenbergFit, fit_onset, fit_swift_hohenberg

__all__ = ["NoOnset", "OnsetFit", "SwiftHohenbergFit", "fit_onset", "fit_swift_hohenberg"]
