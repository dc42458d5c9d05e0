// Replaced by the first real source of neuflow::eval.
