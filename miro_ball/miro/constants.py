"""MiRo-E numbers shared by the simulator and the controller.

Every value comes from the MDK (its ``miro2.constants`` Python module and
``miro_software_constants.h``, releases R191016 to R200720) or from Consequential Robotics'
public MiRo-E documentation (https://labs.consequentialrobotics.com/miro-e/docs/: the
technical pages on the platform's geometry, sensors and interface).
"""
import math

# Drive
WHEEL_RADIUS_M = 0.045
WHEEL_TRACK_M = 0.164
WHEEL_MAX_SPEED_M_PER_S = 0.4
PLATFORM_TICK_S = 0.02  # 50 Hz sensor and control tick

# Kinematic chain; index order of every kinematic_joints message.
JOINT_NAMES = ('tilt', 'lift', 'yaw', 'pitch')
# What a reader of a JointState of the neck wants, in words.
JOINT_POSITIONS = f'positions [{", ".join(JOINT_NAMES)}]'
TILT, LIFT, YAW, PITCH = range(4)
TILT_RAD = math.radians(-6.0)  # fixed pseudo-joint: the body rests tilted back
JOINT_LIMITS_RAD = (
    (TILT_RAD, TILT_RAD),
    (math.radians(8.0), math.radians(60.0)),
    (math.radians(-55.0), math.radians(55.0)),
    (math.radians(-22.0), math.radians(8.0)),
)
LIFT_RAD_CALIB = math.radians(34.0)
KIN_CALIB_RAD = (TILT_RAD, LIFT_RAD_CALIB, 0.0, 0.0)

# Cosmetic joints: droop, wag, eyelid l/r, ear l/r, each 0..1.
COSMETIC_CALIB = (0.0, 0.5, 0.0, 0.0, 1.0 / 3.0, 1.0 / 3.0)

# Speaker: control/stream's samples, control/tone's frequency and volume.
SPEAKER_SAMPLE_RATE_HZ = 8000
TONE_FREQUENCY_RANGE_HZ = (200.0, 2000.0)  # the MDK's interface clips to this
TONE_VOLUME_MAX = 255

# Microphones: sensors/mics carries 4 channels x
# 500 samples at 20 kHz, channel-blocked (data[0:500] is channel 0), 40 messages a second;
# the channels are the frames of miro.body.MICS, in this order (MIC_L 0, MIC_R 1, MIC_C 2,
# MIC_T 3). Full scale is the int16 range.
MIC_SAMPLE_RATE_HZ = 20000
MIC_BLOCK_SAMPLES = 500
MIC_L, MIC_R, MIC_C, MIC_T = range(4)
MIC_FULL_SCALE = 32768
SPEED_OF_SOUND_M_S = 343.0

# Cameras
CAM_ELEVATION_RAD = math.radians(45.0)
CAM_DIVERGENCE_RAD = math.radians(27.0)
CAM_HFOV_DEG_SIM = 120.0
# The real lens's half fields of view on the 16:9 frame (MDK CAM_HORI/VERT_HALF_FOV).
CAM_HORI_HALF_FOV_RAD = math.radians(60.6)
CAM_VERT_HALF_FOV_RAD = math.radians(31.8)
FRAME_SIZES = ((1280, 720), (640, 360), (320, 240))

# Cliff: a value below this is a drop; a sensor sees the floor up to CLIFF_RANGE (m) along
# its ray.
CLIFF_THRESHOLD = 0.7
CLIFF_RANGE = 0.5

# Sonar: an echo from SONAR_RANGE (m) within a cone of radius 0.309 m at 1 m.
SONAR_RANGE = (0.03, 1.0)
SONAR_HALF_CONE = math.atan(0.309)  # rad

# Flags
UPSTREAM_FLAG_SIMULATOR = 1 << 15
DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX = 1 << 21

