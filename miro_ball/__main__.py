from miro_ball.controller.kick_blue_ball import main

main()
