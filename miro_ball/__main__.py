from miro_ball.node import main

main()
