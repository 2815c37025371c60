from miro_ball.gui.app import main

main()
