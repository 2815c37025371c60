"""Running the nodes: start and stop their processes, watch a run, play an episode."""
