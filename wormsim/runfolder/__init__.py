"""A run's folder and its life: writer (atomic writes, one writer at a time, what an interrupt or a failure leaves
behind), interrupt (Ctrl-C and SIGTERM), progress (the bar or the log lines)."""
