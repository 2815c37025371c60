from miro_ball.controller.node import main

main()
