"""The marker-set templates shipped with the package (``src/loper_analysis/templates/``).

Each ``*.yaml`` file there is one template (:class:`loper_analysis.motion.marker_templates.MarkerTemplate`);
the models they name lie beside them.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from loper_analysis.io.readers import read_yaml
from loper_analysis.motion.marker_templates import MarkerTemplate, template_from_spec

__all__ = ["TEMPLATE_DIR", "read_templates", "template_file"]

#: The folder of the templates and their models.
TEMPLATE_DIR: Path = Path(str(resources.files("loper_analysis") / "templates"))


def read_templates() -> dict[str, MarkerTemplate]:
    """Every template of :data:`TEMPLATE_DIR`, by name (the file's stem), in name order."""
    return {
        path.stem: template_from_spec(path.stem, read_yaml(path, "marker-set template"), str(path))
        for path in sorted(TEMPLATE_DIR.glob("*.yaml"))
    }


def template_file(name: str) -> Path:
    """A file of the templates' folder (a template's model)."""
    return TEMPLATE_DIR / name
