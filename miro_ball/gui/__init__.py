"""miro_gui: MiRo's GUI as a web page (python -m miro_ball.gui)."""
