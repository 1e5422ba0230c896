"""io/marker_templates.py: the templates shipped in the package folder, each read as its YAML file says."""

from __future__ import annotations

import yaml

from loper_analysis.io.marker_templates import NOT_A_TEMPLATE, TEMPLATE_DIR, template_file
from loper_analysis.motion.marker_templates import template_from_spec
from loper_analysis.stages.templates import read_templates


def test_every_yaml_file_but_the_synonym_table_is_one_template_by_its_stem():
    templates = read_templates()
    files = sorted(p.stem for p in TEMPLATE_DIR.glob("*.yaml") if p.name != NOT_A_TEMPLATE)
    assert list(templates) == files == ["isb", "plugin_gait"]
    assert (TEMPLATE_DIR / NOT_A_TEMPLATE).is_file()  # the label matcher's synonyms, beside the templates
    for name, template in templates.items():
        path = TEMPLATE_DIR / f"{name}.yaml"
        assert template == template_from_spec(name, yaml.safe_load(path.read_text()), str(path))
        assert template.name == name


def test_each_templates_model_lies_beside_it():
    for template in read_templates().values():
        assert template.model == "gait2392_simbody.osim"
        assert template_file(template.model) == TEMPLATE_DIR / "gait2392_simbody.osim"
        assert template_file(template.model).is_file()
    assert read_templates()["isb"].side_prefix == {"left": "L_", "right": "R_"}
