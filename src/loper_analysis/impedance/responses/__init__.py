"""Perturbation responses: matched unperturbed strides, paired windows, outliers, subject averages.

For each perturbed stride an unperturbed counterfactual is its reference: its own continuation predicted
from its pre-onset course by all unperturbed strides of the onset's trials (``conditional``, the default),
or the unperturbed stride of the same trial that is most similar just before the onset (the study's
``matched_stride``); the response is perturbed minus counterfactual; pairs are judged by the IQR outlier
rule on the analysis window only and averaged per subject and onset. The averaged pair is also what the
identification (:func:`loper_analysis.impedance.identification.prepare_window`) fits.

* :mod:`.matching` - :func:`too_short` (perturbed strides whose swing cannot
  hold the window) and :func:`match_unperturbed` (the matched unperturbed
  stride and its anchor);
* :mod:`.windows` - :func:`paired_windows` (perturbed and matched
  unperturbed windows on one relative time grid, onset at t = 0) and
  :func:`window_outliers` (the IQR rule on the analysis window of the
  differences);
* :mod:`.average` - :func:`subject_onset_response`: all of it for one
  subject and onset, over the subject's trials: the mean response table,
  the stride counts and the averaged series for the identification;
* :mod:`.conditional` - the conditional counterfactual: the ridge prediction of a
  stride's window from its pre-onset samples, its candidates and null pairs;
* :mod:`.null_pairs` - :func:`null_pair_windows`: unperturbed strides paired
  the same way, the stride-to-stride noise the identification weights its
  errors by (a trial whose null pairs deviate far more than the other
  trials' is left out: :func:`deviant_trials`);
* :mod:`.response_window` - :class:`ResponseWindow`: the analysis window around the onset and the span
  before it for the fit's initial state, which the fit, the planner and the validation study share;
* :mod:`.inputs` and :mod:`.sampling` - the trial inputs (frames) and the
  spline sampling the others share.

Conventions
-----------
* Times in s on the motion-capture clock; angles in rad (flexion and
  dorsiflexion positive); forces in N; ``pelvis_x`` in m.
* Alignment: a candidate unperturbed stride ``u`` is aligned to a perturbed
  stride ``p`` at the same time after its own toe-off,
  ``anchor_u = toe_off_u + (onset_p - toe_off_p)``; relative time 0 is the
  onset in ``p`` and the anchor in ``u``.
* Interpolation: samples at times between frames come from a cubic spline
  (:class:`scipy.interpolate.CubicSpline`, not-a-knot) through the frames of
  the run of finite samples that holds the window; at frame times it returns
  the frame values. NaN policy: a window must lie inside one run of finite
  samples (NaN elsewhere, e.g. forces outside the robot log, is allowed).
"""

from loper_analysis.impedance.responses.average import COUNT_COLUMNS, subject_onset_response
from loper_analysis.impedance.responses.matching import MATCH_COLUMNS, match_unperturbed, too_short
from loper_analysis.impedance.responses.null_pairs import (
    MAX_TRIAL_DEVIATION_RATIO,
    deviant_trials,
    null_pair_windows,
    trial_deviation_rad,
)
from loper_analysis.impedance.responses.response_window import ResponseWindow
from loper_analysis.impedance.responses.windows import (
    MIN_PAIRS_FOR_OUTLIERS,
    ResponseSettings,
    analysis_grid,
    paired_windows,
    window_outliers,
)

__all__ = [
    "MATCH_COLUMNS",
    "COUNT_COLUMNS",
    "MIN_PAIRS_FOR_OUTLIERS",
    "ResponseSettings",
    "ResponseWindow",
    "analysis_grid",
    "too_short",
    "match_unperturbed",
    "paired_windows",
    "window_outliers",
    "subject_onset_response",
    "null_pair_windows",
    "MAX_TRIAL_DEVIATION_RATIO",
    "trial_deviation_rad",
    "deviant_trials",
]
