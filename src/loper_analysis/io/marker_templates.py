"""The marker-set templates shipped with the package (``src/loper_analysis/templates/``).

Each ``*.yaml`` file there but ``label_synonyms.yaml`` (the label matcher's landmark synonyms),
read by :mod:`loper_analysis.io.label_synonyms`, is one template's specification, read here as it is; the
file layer builds the templates from them (:func:`loper_analysis.stages.templates.read_templates`,
:func:`loper_analysis.motion.marker_templates.template_from_spec`). The models they name lie beside them.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from loper_analysis.io.readers import read_yaml

__all__ = ["NOT_A_TEMPLATE", "TEMPLATE_DIR", "read_template_specs", "template_file"]

#: The folder of the templates and their models.
TEMPLATE_DIR: Path = Path(str(resources.files("loper_analysis") / "templates"))
#: The YAML file of the folder that is no template: the label matcher's landmark synonyms.
NOT_A_TEMPLATE = "label_synonyms.yaml"


def read_template_specs() -> dict[str, tuple[dict, str]]:
    """Every template's specification of :data:`TEMPLATE_DIR` as read, with its file: name (the file's stem) ->
    (specification, path), in name order (the synonym table ``label_synonyms.yaml`` is none)."""
    return {
        path.stem: (read_yaml(path, "marker-set template"), str(path))
        for path in sorted(TEMPLATE_DIR.glob("*.yaml"))
        if path.name != NOT_A_TEMPLATE
    }


def template_file(name: str) -> Path:
    """A file of the templates' folder (a template's model)."""
    return TEMPLATE_DIR / name
