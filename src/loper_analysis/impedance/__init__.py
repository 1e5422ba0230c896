"""The impedance stage's science: the perturbation responses (:mod:`.responses`: windows, matched
unperturbed strides, averages and null pairs) and their identification (:mod:`.identification`: the
swing-leg fits, intervals, statuses and the validation study's fits)."""
