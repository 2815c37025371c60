"""The wheel command a script holds: stop() is the last word even when the executor's
re-send runs at the same moment."""
import threading

from miro_ball.robot.held_command import HeldCommand

WAIT_S = 10.0  # wall seconds: only against a hang


def test_holds_until_released():
    sent = []
    wheels = HeldCommand(lambda *command: sent.append(command))
    wheels.repeat()
    wheels.hold(0.1, 0.5)
    wheels.repeat()
    wheels.release()
    wheels.repeat()
    assert sent == [(0.1, 0.5), (0.1, 0.5), (0.0, 0.0)]


def test_a_stop_during_a_re_send_is_sent_after_it():
    sent = []
    resending, go_on = threading.Event(), threading.Event()

    def send(*command):
        if threading.current_thread().name == 'executor':
            resending.set()  # the re-send has read the held command and is publishing it
            assert go_on.wait(WAIT_S)
        sent.append(command)

    wheels = HeldCommand(send)
    wheels.hold(0.0, 0.2)
    executor = threading.Thread(target=wheels.repeat, name='executor')
    executor.start()
    assert resending.wait(WAIT_S)
    stopper = threading.Thread(target=wheels.release)
    stopper.start()
    stopper.join(0.2)  # stop() waits for the re-send under way (unlocked, it would not)
    go_on.set()
    executor.join(WAIT_S)
    stopper.join(WAIT_S)
    assert not executor.is_alive() and not stopper.is_alive()
    assert sent[-1] == (0.0, 0.0)
