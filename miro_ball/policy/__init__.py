"""A trained policy as a controller of the contract: its files (``files``), the linear
policy (``linear``), the observation it reads (``observation``, the learning environments'
own) and the controller that runs it (``controller``). Training is miro_ball.learn's; this
package loads neither Gymnasium nor PyBullet, so a controller node runs a policy without
them."""
