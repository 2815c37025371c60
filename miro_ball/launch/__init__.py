"""Launch files (ROS 2's XML and YAML formats) run without ROS 2's launch: ``python -m
miro_ball.launch``. ``entities`` reads a file, ``substitutions`` fills in ``$(...)``,
``plan`` turns a file and its arguments into the processes to start, ``executables`` says
each one's command line, ``exits`` what to do when one ends, ``runner`` runs them."""


class LaunchError(ValueError):
    """A launch file, or an argument given to it, that can not be run: one line says why."""
