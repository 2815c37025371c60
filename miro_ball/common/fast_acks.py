"""Acknowledgements within tens of milliseconds, for the last message a node sends.

A reader acknowledges a reliable writer's messages when the writer asks (a heartbeat),
and Fast DDS's writers ask every 3 s. A node that on its way out waits for its last
message (the controller's zero twist) to be acknowledged, with a bound of 0.5 s, waited
the whole bound on nearly every stop (measured: 0.4-2 s for an acknowledgement between two
processes here; 55-60 ms with a heartbeat every 50 ms, which costs nothing measurable on a
loopback). The message itself has left when publish() returns (rmw_fastrtps publishes
synchronously); the wait is for the confirmation.
"""
import os
import tempfile
from pathlib import Path

ENV = 'FASTRTPS_DEFAULT_PROFILES_FILE'
# Fast DDS 3's name for the same; a user's profile under either name is theirs to keep.
ENV_NEW = 'FASTDDS_DEFAULT_PROFILES_FILE'
WRITER = """  <data_writer profile_name="miro_writer" is_default_profile="true">
    <times><heartbeatPeriod><sec>0</sec><nanosec>50000000</nanosec></heartbeatPeriod></times>
  </data_writer>
"""


def profile(*elements):
    """A Fast DDS profiles file's text holding elements."""
    return ('<?xml version="1.0" encoding="UTF-8" ?>\n'
            '<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">\n'
            + ''.join(elements) + '</profiles>\n')


def use_fast_acks(environ=os.environ):
    """Give this process's writers (and its children's) the fast heartbeat, before
    rclpy.init, unless the user chose a profiles file of their own."""
    if environ.get(ENV) or environ.get(ENV_NEW):
        return
    path = Path(tempfile.gettempdir()) / f'miro_ball_fast_acks_{os.getuid()}.xml'
    text = profile(WRITER)
    try:
        if not path.is_file() or path.read_text() != text:
            staged = path.with_name(f'{path.name}.{os.getpid()}')
            staged.write_text(text)
            os.replace(staged, path)  # whole, for a program starting beside this one
    except OSError:  # no writable temporary folder: the default heartbeat, slower stops
        return
    environ[ENV] = str(path)
