"""OpenSim external loads (io.external_loads): the ground-reaction ``.mot`` read back as written (by the reader
and by OpenSim's Storage), the ExternalLoads setup read back by OpenSim with one ExternalForce per plate, and bad
tables and plate maps named by file and value."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.grf import external_loads_columns
from loper_analysis.io.external_loads import write_external_loads_mot, write_external_loads_xml
from loper_analysis.io.opensim_tables import read_mot
from loper_analysis.io.osim import quiet_opensim


def _loads(rng, n=6, plates=(1, 2)) -> pd.DataFrame:
    names = [c for p in plates for c in external_loads_columns(p)]
    frame = pd.DataFrame(rng.normal(scale=100.0, size=(n, len(names))), columns=names)
    frame.insert(0, "time_s", np.arange(n) / 1000.0 + 0.5)
    return frame


def test_the_loads_read_back_as_written(tmp_path, rng):
    """18 columns of two plates, N, m and N·m as given (no degrees): back to 1e-14, time column ``time``."""
    frame = _loads(rng)
    frame.iloc[2, 5] = np.nan
    path = write_external_loads_mot(tmp_path / "grf.mot", frame)
    text = path.read_text()
    assert text.startswith("ExternalLoads\ninDegrees=no\n")
    assert "\ntime\t1_ground_force_vx\t1_ground_force_vy\t" in text
    back = read_mot(path)
    assert list(back.columns) == list(frame.columns)
    np.testing.assert_allclose(back.to_numpy(), frame.to_numpy(), rtol=1e-14, atol=0)  # NaN where NaN
    storage = quiet_opensim().Storage(str(path))
    assert storage.getSize() == len(frame)
    labels = storage.getColumnLabels()
    assert [labels.get(i) for i in range(labels.getSize())] == ["time", *frame.columns[1:]]


@pytest.mark.parametrize(
    "name, change, message",
    [
        ("grf.trc", lambda f: f, r"grf.trc: expected a .mot or .sto file, got suffix '.trc'"),
        ("grf.mot", lambda f: f[["time_s"]], r"grf.mot: frame needs load column\(s\) besides time_s"),
        ("grf.mot", lambda f: f.drop(columns="time_s"), r"grf.mot: frame must be a DataFrame with a 'time_s' column"),
        (
            "grf.mot",
            lambda f: f.assign(**{"1_ground_force_vz": [0, 1, np.inf, 3, 4, 5]}),
            r"grf.mot: column '1_ground_force_vz' is infinite at row 2",
        ),
    ],
)
def test_a_bad_table_is_named_and_nothing_written(tmp_path, rng, name, change, message):
    with pytest.raises(LoperInputError, match=message):
        write_external_loads_mot(tmp_path / name, change(_loads(rng)))
    assert not (tmp_path / name).exists()


def test_opensim_reads_one_external_force_per_plate(tmp_path):
    """Plates 2 and 1 onto the left and right heels: OpenSim reads the setup back, plates in number order, each
    with its body, its identifiers and ground as the frame of its force and point."""
    path = write_external_loads_xml(tmp_path / "grf.xml", {2: "calcn_l", 1: "calcn_r"}, "grf.mot", name="walk01")
    loads = quiet_opensim().ExternalLoads(str(path), True)
    assert (loads.getName(), loads.getDataFileName(), loads.getSize()) == ("walk01", "grf.mot", 2)
    read = [
        (
            f.getName(),
            f.get_applied_to_body(),
            f.get_force_identifier(),
            f.get_point_identifier(),
            f.get_torque_identifier(),
            f.get_force_expressed_in_body(),
            f.get_point_expressed_in_body(),
            f.get_data_source_name(),
        )
        for f in (loads.get(i) for i in range(loads.getSize()))
    ]
    assert read == [
        (
            "plate1",
            "calcn_r",
            "1_ground_force_v",
            "1_ground_force_p",
            "1_ground_torque_",
            "ground",
            "ground",
            "grf.mot",
        ),
        (
            "plate2",
            "calcn_l",
            "2_ground_force_v",
            "2_ground_force_p",
            "2_ground_torque_",
            "ground",
            "ground",
            "grf.mot",
        ),
    ]


@pytest.mark.parametrize(
    "bodies, message",
    [
        ({}, "bodies must map at least one plate number to a body"),
        ({0: "calcn_r"}, "plate numbers must be integers >= 1, got 0"),
        ({True: "calcn_r"}, "plate numbers must be integers >= 1, got True"),
        ({"1": "calcn_r"}, "plate numbers must be integers >= 1, got '1'"),
        ({1: " calcn_r"}, "plate 1: body name must be a non-empty name, got ' calcn_r'"),
        ({1: ""}, "plate 1: body name must be a non-empty name, got ''"),
    ],
)
def test_a_bad_plate_map_is_named_and_nothing_written(tmp_path, bodies, message):
    path = tmp_path / "grf.xml"
    with pytest.raises(LoperInputError) as err:
        write_external_loads_xml(path, bodies, "grf.mot")
    assert str(err.value) == f"{path}: {message}"
    assert not path.exists()
