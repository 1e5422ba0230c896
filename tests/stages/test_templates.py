"""The shipped marker-set templates read and built for the file steps: every specification of the templates
folder becomes its template, by name, and a template names the model file beside it."""

from __future__ import annotations

from loper_analysis.io.marker_templates import read_template_specs, template_file
from loper_analysis.stages.templates import read_templates


def test_every_specification_becomes_its_template():
    specs, templates = read_template_specs(), read_templates()
    assert list(templates) == list(specs) == sorted(specs)
    assert {"isb", "plugin_gait"} <= set(templates)
    for name, template in templates.items():
        assert template.name == name
        assert template_file(template.model).is_file(), template.model
    assert templates["plugin_gait"].joint_centres is not None and templates["isb"].joint_centres is None
