"""The benchmarks (simulator, renderers, controller, GUI, scenarios) and the soak."""
