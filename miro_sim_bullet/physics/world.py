"""The simulated world without ROS: one PyBullet client, its bodies, its robots, time.

SimWorld is what the ROS node wraps and what tests drive directly: build a world
from its description, step it, move things, read the ground truth. Nothing here
sleeps or looks at the wall clock, and nothing draws: the cameras
(render.cameras.Cameras) take a world and draw its client's bodies.
"""
import math
import os
import tempfile
from dataclasses import replace

from miro_ball.miro.constants import PLATFORM_TICK_S
from miro_ball.miro.interface import BALL_NAME, default_robot_name
from miro_ball.miro.rotations import yaw_of
from miro_sim_bullet.acoustics.hearing import Acoustics
from miro_sim_bullet.bullet import pybullet as pb
from miro_sim_bullet.physics.robot import MiroRobot
from miro_sim_bullet.physics.sensors import GRAVITY
from miro_sim_bullet.scene.world_file import load_world
from miro_sim_bullet.scene.world_model import (half_extents, MAX_ROBOTS, MAX_SHAPES,
                                               PICTURE_UV, RobotSpec, Shape, table_of, World)

# Collision groups. Bit 0 stays in every mask because Bullet's ray tests carry group 1.
# Static bodies skip each other (a wall panel touching the floor is work for nothing);
# movable objects and robots meet everything. Each robot has a bit of its own, so its
# sensor rays see the world and the other robots but never itself.
# The physics step: 2 ms. The MDK uses 1 ms; at 2 ms driving, turning, kicking, wall and
# cliff behaviour and the scenario benchmark's kicks are the same (README "Simulator
# parameters", BENCHMARKS.md) and physics costs half as much.
PHYSICS_DT_S = 0.002
# Constraint solver iterations per step. PyBullet's default, 50, costs 20 % more physics
# than 10, and MiRo's contacts (two wheels, a slider, a ball) settle well within 10: the
# physical tests and the scenario benchmark are the same (BENCHMARKS.md, speed round 2).
# 5 cost a tenth less than 10 with robots driving (issue 49), and MiRo drives, turns, lifts
# its head and pushes the ball as with 10 or 50 (0.884 m against 0.882 and 0.880 in 3 s at
# 0.3 m/s, 2.906 rad against 2.910 and 2.912 in 2 s at 1.5 rad/s; docs/body.md).
SOLVER_ITERATIONS = 5
RAY_GROUP = 1
STATIC_GROUP = 1 << 1
MOVABLE_GROUP = 1 << 2
ALL_GROUPS = (1 << (MAX_ROBOTS + 3)) - 1


def robot_group(index):
    return 1 << (index + 3)


class SimWorld:
    """A world with its MiRos in it.

    world: a World or a bundled name / file path. robot_name names the world's robot
    when the file leaves it unnamed (default $MIRO_ROBOT_NAME or 'miro').
    ``generation`` counts the builds: a reset makes every body anew.
    """

    def __init__(self, world='miro', physics_dt=PHYSICS_DT_S, robot_name=None):
        self.description = world if isinstance(world, World) else load_world(world)
        self.robot_name = robot_name or default_robot_name()
        self.dt = physics_dt
        self.ticks_per_platform_tick = max(1, round(PLATFORM_TICK_S / physics_dt))
        self.loaded = self.description  # as loaded: what a full reset goes back to
        self.client = pb.connect(pb.DIRECT)
        self.generation = 0
        self.spawned = set()  # names of the entities added at run time (spawn())
        self._build()

    # -- building -----------------------------------------------------------------------------
    def _kw(self):
        return {'physicsClientId': self.client}

    def _build(self, keep_time=False):
        kw = self._kw()
        pb.resetSimulation(**kw)
        pb.setPhysicsEngineParameter(fixedTimeStep=self.dt, deterministicOverlappingPairs=1,
                                     numSolverIterations=SOLVER_ITERATIONS, **kw)
        pb.setGravity(0, 0, -GRAVITY, **kw)
        if not keep_time:
            self.step_index = 0
        world = self.description
        # body id -> (name or group, 'static' | 'mover' | 'robot'): what the scene calls it.
        self.body_labels = {}
        self._probes = {}  # half extents -> a collision shape for statics_within()
        self.shape_of = {}  # body id -> the world_model Shape (or Ball) it was made from
        if world.ground_height is not None:
            plane = Shape(kind='box', position=(0, 0, world.ground_height - 0.05),
                          size=(*world.ground_size, 0.1), colour=world.ground_colour,
                          source='ground')
            ground = self._shape(plane)
            self.body_labels[ground] = ('ground', 'static')
            self.shape_of[ground] = plane
        self.objects = {}  # name -> body id of everything movable but the robots
        self.statics = {}  # name -> body id of the named static shapes
        for shape in world.shapes:
            self._add_shape(shape)
        self.ball_id = None
        if world.ball is not None:
            self._add_ball(world.ball)
        self.robots = {}
        self._bits = {}  # robot name -> its collision group's bit number
        for spec in world.robots:
            self._add_robot(spec)
        self.unnamed = self._name_unnamed()
        self.picture_bodies = self._pictures()  # last, so that the other bodies keep their ids
        self._filter_collisions()
        self._new_acoustics()
        self.generation += 1
        self._built = self._movers_state()

    def _name_unnamed(self):
        """{body id: '<table>_<k>'} of the ground and the unnamed static shapes: the k-th of
        its world-file table in the world as loaded, so that neither a deletion nor a
        rebuild renames another (deleting 'wall_3' twice deleted two walls)."""
        loaded = {'ground': [None]}  # the ground is 'ground_0'
        for shape in self.loaded.shapes:
            if not shape.name and shape.mass <= 0:
                loaded.setdefault(table_of(shape), []).append(shape)
        looked = dict.fromkeys(loaded, 0)  # where the next of each table is looked for
        names = {}
        for body, shape in self.shape_of.items():
            label, kind = self.body_labels[body]
            if kind != 'static' or shape.name:
                continue
            candidates = loaded.setdefault(label, [])
            index = looked.setdefault(label, 0)
            if label != 'ground':
                while index < len(candidates) and candidates[index] != shape:
                    index += 1
            names[body] = f'{label}_{index}'
            looked[label] = index + 1
        return names

    def _add_ball(self, ball):
        self.ball_id = self._shape(Shape(
            kind='sphere', position=(*ball.position, ball.floor + ball.radius),
            radius=ball.radius, colour=ball.colour, mass=ball.mass, friction=ball.friction,
            restitution=ball.restitution, name=BALL_NAME, source='ball'))
        self.objects[BALL_NAME] = self.ball_id
        self.body_labels[self.ball_id] = (BALL_NAME, 'mover')
        self.shape_of[self.ball_id] = ball

    def _add_shape(self, shape):
        body = self._shape(shape)
        self.shape_of[body] = shape
        if shape.mass > 0:
            self.objects[shape.name] = body
            self.body_labels[body] = (shape.name, 'mover')
        else:
            if shape.name:
                self.statics[shape.name] = body
            self.body_labels[body] = (shape.name or table_of(shape), 'static')
        return body

    def _add_robot(self, spec):
        name = spec.name or self.robot_name
        bit = min(set(range(MAX_ROBOTS)) - set(self._bits.values()))
        robot = MiroRobot(self.client, name, spec, clock=lambda: self.time,
                          ray_mask=ALL_GROUPS & ~robot_group(bit))
        self._bits[name] = bit
        self.robots[name] = robot
        self.body_labels[robot.body_id] = (name, 'robot')
        return robot

    def _filter_collisions(self):
        """Every body in its collision group. Setting a body's filter also empties Bullet's
        cache of its contacts, which a restored snapshot keeps (rewind())."""
        kw = self._kw()
        movable = set(self.objects.values())
        for name, robot in self.robots.items():
            robot.model.set_collision_filter(robot_group(self._bits[name]), ALL_GROUPS)
        # The robots' own filters are set above; the pictures and drawn parts, which have
        # no collision shape, meet nothing from when they are made.
        skipped = {*self.picture_bodies, *(body for robot in self.robots.values()
                                           for body in (robot.body_id,
                                                        *robot.model.drawn.bodies.values()))}
        for body in (pb.getBodyUniqueId(k, **kw) for k in range(pb.getNumBodies(**kw))):
            if body in skipped:
                continue
            if body in movable:
                pb.setCollisionFilterGroupMask(body, -1, MOVABLE_GROUP, ALL_GROUPS, **kw)
            else:
                pb.setCollisionFilterGroupMask(body, -1, STATIC_GROUP,
                                               ALL_GROUPS & ~STATIC_GROUP, **kw)

    def _new_acoustics(self, playing=()):
        """The world's sound for the robots there are now; ``playing``: sounds added at run
        time that go on (scene.sounds.Sound)."""
        world = self.description
        self.acoustics = Acoustics(self.robots, world.sounds, world.hearing,
                                   ground=world.ground_height or 0.0)
        for sound in playing:
            self.acoustics.add_sound(sound)

    def _shape(self, shape):
        kw = self._kw()
        if shape.kind == 'box':
            dims = {'halfExtents': half_extents(shape)}
            cdims = dims
        elif shape.kind == 'cylinder':
            dims = {'radius': shape.radius, 'length': shape.length}
            cdims = {'radius': shape.radius, 'height': shape.length}
        else:
            dims = cdims = {'radius': shape.radius}
        geom = {'box': pb.GEOM_BOX, 'cylinder': pb.GEOM_CYLINDER, 'sphere': pb.GEOM_SPHERE}
        col = pb.createCollisionShape(geom[shape.kind], **cdims, **kw)
        vis = pb.createVisualShape(geom[shape.kind], rgbaColor=(*shape.colour, 1), **dims, **kw)
        # What does not move is a static rigid body (maximal coordinates): Bullet steps a
        # fixed multibody every physics step, a static rigid body not at all (the default
        # world's step 20 % cheaper with the pictures and drawn parts as such too).
        body = pb.createMultiBody(shape.mass, col, vis, shape.position,
                                  pb.getQuaternionFromEuler((0, 0, shape.yaw)),
                                  useMaximalCoordinates=shape.mass <= 0, **kw)
        pb.changeDynamics(body, -1, lateralFriction=shape.friction,
                          restitution=shape.restitution, **kw)
        return body

    def _pictures(self):
        """A visual-only static body per picture, a textured quad, for PyBullet's
        TinyRenderer; their ids. Our GL renderer draws World.pictures itself; it skips these
        meshes."""
        kw = self._kw()
        textures = {}  # one texture per image file
        bodies = []
        for picture in self.description.pictures:
            if picture.image not in textures:
                textures[picture.image] = _texture(picture.png, kw)
            corners = [list(c) for c in picture.corners]
            edge_a = [b - a for a, b in zip(corners[0], corners[1])]
            edge_b = [b - a for a, b in zip(corners[0], corners[3])]
            normal = [edge_a[1] * edge_b[2] - edge_a[2] * edge_b[1],
                      edge_a[2] * edge_b[0] - edge_a[0] * edge_b[2],
                      edge_a[0] * edge_b[1] - edge_a[1] * edge_b[0]]
            length = math.sqrt(sum(n * n for n in normal)) or 1.0
            visual = pb.createVisualShape(
                pb.GEOM_MESH, vertices=corners, indices=[0, 1, 2, 0, 2, 3],
                # TinyRenderer's texture v runs up from the image's bottom row (OBJ's way).
                uvs=[(u, 1.0 - v) for u, v in PICTURE_UV],
                normals=[[n / length for n in normal]] * 4, **kw)
            body = pb.createMultiBody(0, -1, visual, (0, 0, 0), useMaximalCoordinates=True, **kw)
            pb.setCollisionFilterGroupMask(body, -1, 0, 0, **kw)  # no pairs with anything
            pb.changeVisualShape(body, -1, textureUniqueId=textures[picture.image],
                                 rgbaColor=(1, 1, 1, 1), **kw)
            bodies.append(body)
        return bodies

    def reset(self):
        """Back to the world as loaded, time zero: what was spawned since is gone, what was
        deleted is back. Rewound (rewind(): the simulator's reset between episodes) when no
        body came or went since the world was built, else built from scratch."""
        if self.description is self.loaded:
            self.rewind()
        else:
            self.rebuild()

    def rebuild(self):
        """Back to the world as loaded, time zero, every body made anew (a renderer plugin
        loaded since sees them all)."""
        self.description, self.spawned = self.loaded, set()
        self._build()

    def reset_state(self):
        """Everything there is now back to where it started (a spawned entity: where it
        was spawned), time going on."""
        self._build(keep_time=True)

    def reset_time(self):
        """Time from zero; nothing moves."""
        self.step_index = 0

    def load(self, world):
        """Another world in place of this one (a World), built from scratch, time zero."""
        self.loaded = world
        self.rebuild()

    # -- entities added and removed at run time -----------------------------------------------
    def names(self):
        """Every name in use: robots, movable objects (the ball among them), named statics."""
        return {*self.robots, *self.objects, *self.statics}

    def entities(self):
        """{name: body id} of every body but the drawn parts and pictures: the robots,
        the movable objects, the named statics and the unnamed ones, named '<table>_<k>'
        (the k-th of a world-file table: 'wall_3', 'ring_0', 'ground_0')."""
        named = {**{name: robot.body_id for name, robot in self.robots.items()},
                 **self.objects, **self.statics}
        for body, name in self.unnamed.items():
            named.setdefault(name, body)
        return named

    def built_from(self, name, bodies=None):
        """The world_model Shape or Ball the entity ``name`` (of entities(), or ``bodies``
        when the caller has it already) was built from; None for a robot."""
        if name in self.robots:
            return None
        return self.shape_of[(self.entities() if bodies is None else bodies)[name]]

    def movers(self):
        """{name: body id} of everything that moves: the robots and the movable objects."""
        return {**{name: robot.body_id for name, robot in self.robots.items()}, **self.objects}

    def body_state(self, body):
        """(position, orientation xyzw, linear velocity, angular velocity) of a body's base
        in the world frame."""
        return (*pb.getBasePositionAndOrientation(body, **self._kw()), *self.body_velocity(body))

    def body_velocity(self, body):
        """(linear, angular) velocity of a body's base in the world frame."""
        return pb.getBaseVelocity(body, **self._kw())

    def set_body_velocity(self, body, linear, angular):
        pb.resetBaseVelocity(body, linear, angular, **self._kw())

    def spawn_ball(self, ball):
        """The world's ball (a world_model.Ball: on its floor at its position); ValueError
        if it has one already."""
        if self.ball_id is not None:
            raise ValueError('the world has its ball already')
        self._add_ball(ball)
        pb.setCollisionFilterGroupMask(self.ball_id, -1, MOVABLE_GROUP, ALL_GROUPS,
                                       **self._kw())
        self._added(BALL_NAME, replace(self.description, ball=ball))

    def spawn_robot(self, name, x, y, yaw, floor=0.0):
        """A MiRo named ``name`` standing at (x, y, yaw) on a floor at height ``floor``,
        powered up; ValueError if the world has MAX_ROBOTS already or the name is taken."""
        if len(self.robots) >= MAX_ROBOTS:
            raise ValueError(f'the world has {MAX_ROBOTS} robots, the most it can hold')
        self._check_free(name)
        spec = RobotSpec(name, (float(x), float(y), float(yaw)), float(floor))
        robot = self._add_robot(spec)
        robot.model.set_collision_filter(robot_group(self._bits[name]), ALL_GROUPS)
        self._added(name, replace(self.description,
                                  robots=(*self.description.robots, spec)))
        return robot

    def spawn_shape(self, shape):
        """A named box, sphere or cylinder (world_model.Shape; mass 0 = static); ValueError
        if the world has MAX_SHAPES already (a world file's limit too)."""
        if len(self.description.shapes) >= MAX_SHAPES:
            raise ValueError(f'the world has {MAX_SHAPES} shapes, the most it can hold')
        self._check_free(shape.name)
        body = self._add_shape(shape)
        if shape.mass > 0:
            pb.setCollisionFilterGroupMask(body, -1, MOVABLE_GROUP, ALL_GROUPS, **self._kw())
        else:
            pb.setCollisionFilterGroupMask(body, -1, STATIC_GROUP, ALL_GROUPS & ~STATIC_GROUP,
                                           **self._kw())
        self._added(shape.name, replace(self.description,
                                        shapes=(*self.description.shapes, shape)))

    def movers_within(self, low, high):
        """Names of the movable objects (the ball among them) and robots whose bounding
        boxes reach into the box from corner ``low`` to corner ``high``."""
        found = pb.getOverlappingObjects(low, high, **self._kw()) or ()
        bodies = {body for body, _ in found}
        return sorted(name for name, body in self.movers().items() if body in bodies)

    def statics_within(self, half, centre, yaw):
        """Names of the static bodies (walls, tables, the floor) that a box of ``half``
        extents at ``centre``, turned by ``yaw``, reaches into: by their shapes, not their
        bounding boxes, so that a box beside a turned wall panel is clear of it."""
        kw = self._kw()
        flat = math.hypot(half[0], half[1])  # the box turned any way stays within this
        low = (centre[0] - flat, centre[1] - flat, centre[2] - half[2])
        high = (centre[0] + flat, centre[1] + flat, centre[2] + half[2])
        near = {body for body, _ in pb.getOverlappingObjects(low, high, **kw) or ()}
        if half not in self._probes:  # once a build: Bullet can not free a collision shape
            self._probes[half] = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=half, **kw)
        turn = pb.getQuaternionFromEuler((0, 0, yaw))
        return sorted(name for name, body in self.entities().items()
                      if body in near and self.body_labels[body][1] == 'static'
                      and pb.getClosestPoints(bodyA=-1, bodyB=body, distance=0.0,
                                              collisionShapeA=self._probes[half],
                                              collisionShapePositionA=centre,
                                              collisionShapeOrientationA=turn, **kw))

    def _check_free(self, name):
        if not name or name in self.names():
            raise ValueError(f'the name {name!r} is taken or empty')

    def _added(self, name, description):
        self.description = description
        self.spawned.add(name)
        self._changed()

    def remove(self, name):
        """Take the entity ``name`` (entities()) out of the world; KeyError if there is
        none, ValueError for the ground."""
        kw = self._kw()
        world = self.description
        if name in self.robots:
            robot = self.robots.pop(name)
            del self._bits[name]
            for body in (robot.body_id, *robot.model.drawn.bodies.values()):
                pb.removeBody(body, **kw)
            del self.body_labels[robot.body_id]
            self.shape_of.pop(robot.body_id, None)
            world = replace(world, robots=tuple(
                spec for spec in world.robots if (spec.name or self.robot_name) != name))
        elif name == BALL_NAME and self.ball_id is not None:
            pb.removeBody(self.ball_id, **kw)
            del self.objects[BALL_NAME], self.body_labels[self.ball_id]
            del self.shape_of[self.ball_id]
            self.ball_id = None
            world = replace(world, ball=None)
        else:
            body = self.entities()[name]
            shapes = list(world.shapes)
            if self.shape_of[body] not in shapes:  # checked first: a failure changes nothing
                raise ValueError(f'{name} is the ground: it cannot be deleted')
            self.objects.pop(name, None)
            self.statics.pop(name, None)
            self.unnamed.pop(body, None)
            shapes.remove(self.shape_of.pop(body))
            pb.removeBody(body, **kw)
            del self.body_labels[body]
            world = replace(world, shapes=tuple(shapes))
        self.description = world
        self.spawned.discard(name)
        self._changed()

    def remove_spawned(self):
        """Every entity spawned since the world was loaded (or last reset) taken out."""
        for name in sorted(self.spawned):
            self.remove(name)

    def _changed(self):
        """The set of bodies changed: the robots' sound, the renderers' copy of the scene
        and rewind()'s snapshot follow."""
        self._new_acoustics(source.sound for _, source in self.acoustics.sounds.values()
                            if source.sound not in self.description.sounds)
        self.generation += 1
        self._built = None

    def rewind(self):
        """Back to the state right after the build without building anew (a learning
        environment's reset, and reset()'s when it can: 1 ms where rebuild() took 100 ms for
        the default world, 6 ms against 140 ms for the football pitch, medians of 15 here):
        what moves put back where it was built (_movers_state), time from zero, each
        robot's platform and the world's sound started again. Body ids stay, so renderers
        keep what they read. A world that holds a non-finite value is built anew instead: a
        NaN that reached the physics spoils more than the state a rewind puts back (MiRo sank
        into the floor at every rewind after one NaN head target)."""
        if self._built is None or not self.finite():  # None: bodies were added or removed
            self._build()
            return
        kw = self._kw()
        for body, (pose, velocity, joints) in self._built.items():
            pb.resetBasePositionAndOrientation(body, *pose, **kw)
            pb.resetBaseVelocity(body, *velocity, **kw)
            for joint, (position, speed) in enumerate(joints):
                pb.resetJointState(body, joint, position, speed, **kw)
        # Without this the contacts cached before the rewind warm-start the solver after
        # it, and the same seed no longer gives the same trajectory.
        self._filter_collisions()
        self.step_index = 0
        for robot in self.robots.values():
            robot.start()
        self._new_acoustics()

    def _movers_state(self):
        """{body: (pose, velocity, joint (position, velocity)s)} of everything that moves:
        what rewind() puts back. Not PyBullet's saveState: its restoreState refuses a world
        with static rigid bodies in it, and it copies every body where only these move."""
        kw = self._kw()
        state = {}
        for body in (*self.objects.values(), *(r.body_id for r in self.robots.values())):
            joints = pb.getNumJoints(body, **kw)
            state[body] = (pb.getBasePositionAndOrientation(body, **kw),
                           pb.getBaseVelocity(body, **kw),
                           [s[:2] for s in pb.getJointStates(body, range(joints), **kw)]
                           if joints else [])
        return state

    def finite(self):
        """Whether the pose, velocity and joints of everything that moves are finite."""
        return all(math.isfinite(value) for pose, velocity, joints in
                   self._movers_state().values()
                   for part in (*pose, *velocity, *joints) for value in part)

    def close(self):
        if self.client is not None and pb.isConnected(self.client):
            pb.disconnect(self.client)
        self.client = None

    # -- robots and objects ---------------------------------------------------------------------
    @property
    def robot(self):
        """The first robot: the only one in a single-robot world."""
        return next(iter(self.robots.values()))

    def place_ball(self, x, y):
        """Put the ball at rest on its floor at (x, y)."""
        if self.ball_id is None:
            return
        ball = self.description.ball
        self.set_object_pose(BALL_NAME, (x, y, ball.floor + ball.radius))

    def set_object_pose(self, name, position, orientation=(0.0, 0.0, 0.0, 1.0)):
        """Move a movable object (its centre) or a robot (the point on the floor under its
        axle; only the heading of orientation counts) and stop it. KeyError if unknown. A
        height of None keeps the object's (a robot's: its own floor), an orientation of
        None keeps its orientation (a robot's: its heading)."""
        x, y, z = position
        if name in self.robots:
            robot = self.robots[name]
            if orientation is None:
                yaw = robot.pose()[2]
            else:
                yaw = yaw_of(*orientation)
            robot.place(x, y, yaw, floor=z)
            return
        body = self.objects[name]
        now_position, now_orientation = pb.getBasePositionAndOrientation(body, **self._kw())
        pb.resetBasePositionAndOrientation(
            body, (x, y, now_position[2] if z is None else z),
            now_orientation if orientation is None else orientation, **self._kw())
        pb.resetBaseVelocity(body, (0, 0, 0), (0, 0, 0), **self._kw())

    def object_poses(self):
        """{name: (position, orientation xyzw)} of every movable object."""
        return {name: pb.getBasePositionAndOrientation(body, **self._kw())
                for name, body in self.objects.items()}

    def ball_position(self):
        if self.ball_id is None:
            return None
        return pb.getBasePositionAndOrientation(self.ball_id, **self._kw())[0]

    def touching(self, robot_name, object_name=BALL_NAME):
        """Whether robot robot_name touches movable object_name after the last step."""
        return bool(pb.getContactPoints(bodyA=self.robots[robot_name].body_id,
                                        bodyB=self.objects[object_name], **self._kw()))

    # -- time -----------------------------------------------------------------------------------
    @property
    def time(self):
        return self.step_index * self.dt

    def step(self, n=1, listening=None):
        """Advance n physics steps; every robot's platform ticks every 20 ms of them, and the
        world's sound with it: the microphones of the robots named in ``listening`` (default
        all; the ROS node: those someone listens to) hear each block as it ends."""
        kw = self._kw()
        listening = self.robots if listening is None else listening
        for _ in range(n):
            pb.stepSimulation(**kw)
            self.step_index += 1
            if self.step_index % self.ticks_per_platform_tick == 0:
                for robot in self.robots.values():
                    robot.tick()
                self.acoustics.tick(listening)

    def run(self, seconds, listening=None):
        self.step(round(seconds / self.dt), listening)

    def listen(self, seconds, listening=None):
        """Run ``seconds`` a platform tick at a time; {robot: [acoustics.hearing.MicBlock]} of
        every block the microphones of ``listening`` (default all) heard meanwhile."""
        heard = {}
        for _ in range(round(seconds / PLATFORM_TICK_S)):
            self.step(self.ticks_per_platform_tick, listening)
            for name, robot in self.robots.items():
                if robot.heard is not None:
                    heard.setdefault(name, []).append(robot.heard)
        return heard

    # -- copies ---------------------------------------------------------------------------------
    def snapshot(self):
        """Poses of everything that moves and each robot's joints and LEDs, by name: enough
        for a world built from this one's description to draw the same picture."""
        kw = self._kw()
        bodies = [(name, *pb.getBasePositionAndOrientation(body, **kw))
                  for name, body in self.movers().items()]
        robots = [(name, robot.joint_angles(), list(robot.illum))
                  for name, robot in self.robots.items()]
        return bodies, robots

    def restore(self, snapshot):
        """Pose this world as snapshot() of one built from the same description describes.
        By name, not body id: a copy built from the description of a world that spawned a
        shape numbers its bodies otherwise (the spawned one is no longer the last)."""
        bodies, robots = snapshot
        movers = self.movers()
        for name, position, orientation in bodies:
            pb.resetBasePositionAndOrientation(movers[name], position, orientation,
                                               **self._kw())
        for name, angles, illum in robots:
            robot = self.robots[name]
            robot.set_joint_angles(angles)
            if illum != robot.illum:
                robot.set_illum(illum)


def _texture(png, kw):
    """A PyBullet texture of the PNG bytes checked when the world was read. PyBullet loads a
    texture from a file only: the bytes go to a file of this process's own, not the world
    file's picture again (a link or FIFO put there since would be read unchecked)."""
    with tempfile.TemporaryDirectory(prefix='miro_picture_') as folder:
        path = os.path.join(folder, 'picture.png')
        with open(path, 'wb') as file:
            file.write(png)
        return pb.loadTexture(path, **kw)
