from miro_sim_bullet.node import main

main()
