"""The rows of a fit's inter-joint couplings (loper_analysis.impedance.identification.coupling_rows): their status
against the study's tolerance, worked by hand."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.constants import PARAMETERS
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import ImpedanceFit
from loper_analysis.impedance.identification.coupling_rows import (
    COUPLING_COLUMNS,
    coupling_rows,
    identification_tolerance,
)
from loper_analysis.impedance.identification.impedance import IdentificationSettings

SIX = np.array([40.0, 2.0, 1.0, 0.05, 8.0, 0.3])


def _fit(couplings: dict[str, tuple[float, float]], success: bool = True) -> ImpedanceFit:
    """A fit whose couplings have the given (estimate, 95 % half-width) (N·m/rad) on a t of 18 degrees of freedom."""
    names = PARAMETERS + tuple(f"K_{c}" for c in couplings)
    estimate = np.concatenate([SIX, [v[0] for v in couplings.values()]])
    half = np.concatenate([0.1 * SIX, [v[1] for v in couplings.values()]])
    empty = np.zeros((0, 3))
    return ImpedanceFit(
        estimate=estimate,
        cost=0.0,
        sum_sq_error_rad2=0.0,
        ci95_low=estimate - half,
        ci95_high=estimate + half,
        sd=half / 2.101,
        ci_dof=18,
        correlation=np.eye(len(names)),
        vaf_pct=np.full(3, 90.0),
        success=success,
        message="converged" if success else "iteration limit",
        n_starts=1,
        n_starts_at_best=1,
        n_simulations=1,
        starts=empty,
        start_estimates=empty,
        start_costs=np.zeros(1),
        time_s=np.zeros(0),
        measured=empty,
        model=empty,
        parameters=names,
    )


def test_the_tolerance_is_the_study_s_at_the_coupling_s_size():
    """max(10 % of |K|, 2 N·m/rad): 2 at 0 and at 20, 3 at -30 (N·m/rad); D's max(15 %, 0.05)."""
    assert identification_tolerance("K", 0.0) == 2.0
    assert identification_tolerance("K", 20.0) == 2.0
    assert identification_tolerance("K", -30.0) == pytest.approx(3.0)
    assert identification_tolerance("D", 1.0) == pytest.approx(0.15)
    with pytest.raises(LoperInputError, match="parameter kind"):
        identification_tolerance("C", 1.0)


def test_a_coupling_is_identified_when_its_interval_fits_the_tolerance():
    """Half-width 1.9 at 0: ok; 2.1 at 0: not identifiable, the reason naming both numbers and what says more;
    2.9 at -30 (tolerance 3): ok. One row per coupling in the fit's order, truth 0 for a synthetic subject."""
    table = coupling_rows(_fit({"hip_knee": (0.0, 1.9), "knee_ankle": (0.0, 2.1)}), "S01", 175, 20, truth={})
    assert list(table.columns) == list(COUPLING_COLUMNS)
    rows = table.set_index("coupling")
    assert rows.loc["hip_knee", "status"] == "ok" and rows.loc["hip_knee", "reason"] == ""
    assert rows.loc["knee_ankle", "status"] == "not_identifiable"
    assert "half-width 2.1 N·m/rad exceeds the study's tolerance 2 N·m/rad" in rows.loc["knee_ankle", "reason"]
    assert "plan --couplings" in rows.loc["knee_ankle", "reason"]
    assert rows["K_true_nm_per_rad"].tolist() == [0.0, 0.0] and rows["n_strides"].tolist() == [20, 20]
    large = coupling_rows(_fit({"hip_knee": (-30.0, 2.9)}), "S01", 175, 20).iloc[0]
    assert large["status"] == "ok" and large["tolerance_nm_per_rad"] == pytest.approx(3.0)
    assert np.isnan(large["K_true_nm_per_rad"])  # a recorded subject: no truth


def test_a_coupling_on_its_bound_or_of_a_failed_fit_is_not_reported_as_ok():
    on_bound = coupling_rows(_fit({"hip_knee": (200.0, 1.0)}), "S01", 50, 20).iloc[0]
    assert on_bound["status"] == "not_identifiable" and "on its bound 200" in on_bound["reason"]
    failed = coupling_rows(_fit({"hip_knee": (0.0, 1.0)}, success=False), "S01", 50, 20).iloc[0]
    assert failed["status"] == "failed" and "iteration limit" in failed["reason"]


def test_no_coupling_no_row_and_a_synthetic_truth_may_name_one():
    assert coupling_rows(_fit({}), "S01", 50, 20, truth={}).empty
    rows = coupling_rows(_fit({"hip_knee": (4.0, 1.0)}), "S01", 50, 20, truth={"hip_knee": {"K": 5.0}})
    assert rows.loc[0, "K_error_nm_per_rad"] == pytest.approx(-1.0)


def test_an_unknown_coupling_in_the_settings_names_the_key():
    with pytest.raises(LoperInputError, match=r"impedance.couplings: .*hip_ankle"):
        IdentificationSettings(couplings=("hip_ankle",))
    assert IdentificationSettings(couplings=["knee_ankle", "hip_knee"]).couplings == ("hip_knee", "knee_ankle")
    assert len(IdentificationSettings(couplings=("hip_knee",)).lower) == len(PARAMETERS) + 1
