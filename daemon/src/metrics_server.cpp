// Placeholder: the metrics endpoint is being written.
