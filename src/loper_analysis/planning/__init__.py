"""Planning an experiment: the precision of K and D before anyone walks (the ``planning`` stage).

* :mod:`.inputs` - the planned pulse as the rods deliver it and a pilot's perturbed pairs;
* :mod:`.window` - the planner's settings and the planned experiment's identification window;
* :mod:`.covariance` - the covariance of (K, D) for one perturbed stride, as the fit would estimate it;
* :mod:`.precision` - the predicted standard deviation of each parameter and the strides needed.
"""
