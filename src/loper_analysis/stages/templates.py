"""The marker-set templates shipped with the package, read and built for the file steps that choose or scale with
them (``inspect``, the model stage)."""

from __future__ import annotations

from loper_analysis.io.marker_templates import read_template_specs
from loper_analysis.motion.marker_templates import MarkerTemplate, template_from_spec

__all__ = ["read_templates"]


def read_templates() -> dict[str, MarkerTemplate]:
    """Every template of the package's templates folder, by name (the file's stem), in name order
    (:func:`loper_analysis.io.marker_templates.read_template_specs`)."""
    return {name: template_from_spec(name, spec, source) for name, (spec, source) in read_template_specs().items()}
