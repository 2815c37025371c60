"""The standard simulator interface (simulation_interfaces, Jazzy 1.5.1) under /miro_sim/.

Every service of the standard, named as its type in snake_case relative to the simulator
node (/miro_sim/get_entities_states, ...); the simulate_steps action is step_action's. A
tool written for Gazebo, Isaac Sim or O3DE drives this simulator through them: its state
(playing, paused, stopped, quitting), stepping, resetting by scope, its entities (list,
state, info, bounds, spawn, delete), named poses, spawnable models and worlds.

This module only turns messages into calls and back. What the requests mean is decided by
plain logic (control.*: filters, entities' defaults and bounds, spawn requests, where a
body goes, the state table, pose checks, accelerations) and the world (physics.world.
SimWorld); what they do to time and to the node's interfaces (a robot spawned gets its
topics, a world loaded gets new ones) belongs to the node, reached through ``host``
(node.SimNode). Every refusal is the standard's result code and one line, said as a
rate-limited warning too.
"""
import dataclasses
import traceback

from geometry_msgs.msg import Vector3
from simulation_interfaces import msg as si
from simulation_interfaces import srv

from miro_ball.miro.interface import SimTopics
from miro_ball.miro.rotations import yaw_of, yaw_quaternion
from miro_sim_bullet.control import codes
from miro_sim_bullet.control.accelerations import Accelerations
from miro_sim_bullet.control.codes import EntityCategory, Refused, Result
from miro_sim_bullet.control.entities import (default_entity, entity_bounds, entity_filter,
                                              ROBOT_BOUNDS, tag_filter)
from miro_sim_bullet.control.placement import check_room, spawn_at
from miro_sim_bullet.control.poses import check_pose, check_twist, in_world, WORLD_FRAMES
from miro_sim_bullet.control.spawning import (MAX_RESOURCE_BYTES, parse_spawn, RobotSpawn,
                                              SPAWN_FORMATS, spawnables)
from miro_sim_bullet.control.states import transition
from miro_sim_bullet.ros import convert
from miro_sim_bullet.ros.sim_interface import SERVICE_QOS
from miro_sim_bullet.scene.world_catalogue import world_catalogue, WorldCache
from miro_sim_bullet.scene.world_checks import parse_world
from miro_sim_bullet.scene.world_file import load_world
from miro_sim_bullet.scene.world_model import Ball, named_poses, WorldError

MAX_SPAWNS = 64  # entities one SpawnEntities request may ask for
# A StepSimulation answers when its steps are done, and the simulator does nothing else
# meanwhile: 10 s of simulated time took 0.5 s with one robot, 2.1 s with 16 apart, 3 to
# 12 s with 16 piled on one spot (2 shared cores, 2026-11-26). 2**64-1 steps froze it for
# good. The simulate_steps action steps any number in turns, and can be cancelled.
MAX_STEP_SECONDS = 10.0
RESET_ALL = srv.ResetSimulation.Request.SCOPE_ALL
_F = si.SimulatorFeatures
FEATURES = (
    _F.SPAWNING, _F.DELETING, _F.NAMED_POSES, _F.ENTITY_TAGS, _F.ENTITY_BOUNDS,
    _F.ENTITY_BOUNDS_BOX, _F.ENTITY_CATEGORIES, _F.SPAWNING_RESOURCE_STRING,
    _F.ENTITY_STATE_GETTING, _F.ENTITY_STATE_SETTING, _F.ENTITY_INFO_GETTING,
    _F.ENTITY_INFO_SETTING, _F.SPAWNABLES, _F.SIMULATION_RESET, _F.SIMULATION_RESET_TIME,
    _F.SIMULATION_RESET_STATE, _F.SIMULATION_RESET_SPAWNED, _F.SIMULATION_STATE_GETTING,
    _F.SIMULATION_STATE_SETTING, _F.SIMULATION_STATE_PAUSE, _F.STEP_SIMULATION_SINGLE,
    _F.STEP_SIMULATION_MULTIPLE, _F.STEP_SIMULATION_ACTION, _F.WORLD_LOADING,
    _F.WORLD_RESOURCE_STRING, _F.WORLD_TAGS, _F.WORLD_UNLOADING, _F.WORLD_INFO_GETTING,
    _F.AVAILABLE_WORLDS, _F.SPAWNING_ENTITIES)
CUSTOM_INFO = ('miro_ball: MiRo-E robots in PyBullet. Spawn MiRo-E from its URDF (any '
               'robot_description of ours, or package://miro_ball/robots/miro.urdf) and '
               'balls, boxes, spheres and cylinders from a world file\'s TOML table; worlds '
               'are TOML world files. A robot\'s pose is the point on its floor under the '
               'wheel axle, and its heading.')
# A world that does not load, by what is wrong: there is none, or it breaks a rule.
LOAD_CODES = {WorldError.MISSING: codes.LoadWorld.NO_RESOURCE,
              WorldError.INVALID: codes.LoadWorld.RESOURCE_PARSE_ERROR}


def _result(code=Result.OK, message=''):
    return si.Result(result=code, error_message=message)


class ControlInterface:
    """The services of the standard, made with ros (Endpoints) for ``host``, the node:
    it has ``sim`` (the SimWorld), ``state`` (codes.SimulationState), ``robot_name`` (for
    a world's unnamed robot), ``world_uri`` (of the world loaded), ``sound_folders`` and
    ``world_folders`` (where a client's sound files, and worlds, models and pictures, may
    come from), said(kind, text) (a rate-limited info line) and
    the acts act(action) ('play', 'pause', 'stop', 'quit'), step(n) -> (done, message),
    reset(scope), world_changed() and load(world, uri) / unload(). warn(kind, message) is
    a rate-limited warning, errors(text) logs a failure of ours (with its traceback)."""

    def __init__(self, ros, host, warn, errors):
        self.host, self._warn, self._errors = host, warn, errors
        self.info = {}  # entity name -> Entity (set_entity_info's, or its defaults)
        self.accelerations = Accelerations()
        self._world_cache = WorldCache()  # what get_available_worlds read, asked again
        handlers = {
            srv.GetSimulatorFeatures: self._features, srv.GetSimulationState: self._get_state,
            srv.SetSimulationState: self._set_state, srv.StepSimulation: self._step,
            srv.ResetSimulation: self._reset, srv.GetEntities: self._get_entities,
            srv.GetEntitiesStates: self._get_entities_states,
            srv.GetEntityState: self._get_entity_state,
            srv.SetEntityState: self._set_entity_state, srv.GetEntityInfo: self._get_info,
            srv.SetEntityInfo: self._set_info, srv.GetEntityBounds: self._get_bounds,
            srv.SpawnEntity: self._spawn_entity, srv.SpawnEntities: self._spawn_entities,
            srv.DeleteEntity: self._delete, srv.GetNamedPoses: self._named_poses,
            srv.GetNamedPoseBounds: self._named_pose_bounds,
            srv.GetSpawnables: self._spawnables, srv.GetAvailableWorlds: self._worlds,
            srv.GetCurrentWorld: self._current_world, srv.LoadWorld: self._load_world,
            srv.UnloadWorld: self._unload_world}
        self.services = [ros.service(kind, SimTopics().standard(kind), self._guarded(handler),
                                     qos_profile=SERVICE_QOS)
                         for kind, handler in handlers.items()]

    @property
    def sim(self):
        return self.host.sim

    def _guarded(self, handler):
        """A refusal becomes the response's result (and a warning), whatever the service."""
        def serve(request, response):
            try:
                handler(request, response)
            except Refused as refused:
                self._refuse(handler, response, refused)
            except Exception as err:  # ours, not the client's: answered all the same
                self._errors(f'{handler.__name__[1:]} failed: {err!r}\n'
                             f'{traceback.format_exc()}')
                self._refuse(handler, response, Refused(
                    Result.OPERATION_FAILED, f'the simulator failed: {err!r} (a bug: '
                                             'its log has the details)'))
            return response
        return serve

    def _refuse(self, handler, response, refused):
        self._warn(f'control:{handler.__name__}', f'{handler.__name__[1:]}: {refused}')
        response.result.result, response.result.error_message = refused.code, str(refused)

    # -- the simulation -----------------------------------------------------------------------
    def _features(self, request, response):
        response.features = si.SimulatorFeatures(features=list(FEATURES),
                                                 spawn_formats=list(SPAWN_FORMATS),
                                                 custom_info=CUSTOM_INFO)

    def _get_state(self, request, response):
        response.state.state = self.host.state
        response.result = _result()

    def _set_state(self, request, response):
        self.host.act(transition(self.host.state, request.state.state))
        response.result = _result()

    def _step(self, request, response):
        self._need_world()
        most = round(MAX_STEP_SECONDS / self.sim.dt)
        if not 1 <= request.steps <= most:
            raise Refused(Result.OPERATION_FAILED,
                          f'{request.steps} steps: step_simulation takes 1 to {most} '
                          f'({MAX_STEP_SECONDS:g} s); the simulate_steps action takes more')
        done, message = self.host.step(request.steps)
        if not done:
            raise Refused(Result.OPERATION_FAILED, message)
        response.result = _result()

    def _reset(self, request, response):
        self._need_world()
        scope = request.scope
        if scope & ~0b111 and scope != RESET_ALL:  # 8 read as 0 was a whole reset
            raise Refused(Result.OPERATION_FAILED, f'no reset scope {scope}: 0 or 255 (all), '
                                                   'or a sum of 1 (time), 2 (state), '
                                                   '4 (spawned)')
        self.host.reset(scope)
        response.result = _result()

    def _need_world(self):
        if self.host.state in (codes.SimulationState.NO_WORLD,
                               codes.SimulationState.LOADING_WORLD):
            raise Refused(Result.INCORRECT_STATE, 'no world is loaded: load_world first')

    # -- entities -----------------------------------------------------------------------------
    def entity(self, name, bodies=None):
        """The Entity ``name`` is (its info), or Refused NOT_FOUND (INCORRECT_STATE with
        no world). ``bodies``: sim.entities(), when the caller has it already."""
        self._need_world()
        bodies = self.sim.entities() if bodies is None else bodies
        if name not in bodies:
            shown = ', '.join(sorted(bodies)[:12]) + (', ...' if len(bodies) > 12 else '')
            raise Refused(Result.NOT_FOUND, f'no entity {name[:80]!r}: there are {shown}')
        return self.info.get(name) or default_entity(name, self.sim.built_from(name, bodies))

    def pose(self, name, bodies=None):
        """(position, orientation) of an entity in the world frame; a robot's is its
        FOOT frame: the point on its floor under the axle, turned to its heading."""
        sim = self.sim
        if name in sim.robots:
            x, y, z, yaw = sim.robots[name].ground_truth()
            return (x, y, z), yaw_quaternion(yaw)
        return sim.body_state((sim.entities() if bodies is None else bodies)[name])[:2]

    def _filtered(self, filters):
        """([names the filters keep], sim.entities())"""
        self._need_world()
        keep = entity_filter(filters.filter, [c.category for c in filters.categories],
                             list(filters.tags.tags), filters.tags.filter_mode,
                             (filters.bounds.type,
                              [(p.x, p.y, p.z) for p in filters.bounds.points]))
        # The entities once a request, not once an entity: a world of 2000 shapes.
        bodies = self.sim.entities()
        return [name for name in bodies
                if keep(self.entity(name, bodies), self.pose(name, bodies)[0])], bodies

    def _get_entities(self, request, response):
        response.entities = self._filtered(request.filters)[0]
        response.result = _result()

    def _get_entities_states(self, request, response):
        response.entities, bodies = self._filtered(request.filters)
        response.states = [self.state_of(name, bodies) for name in response.entities]
        response.result = _result()

    def _get_entity_state(self, request, response):
        self.entity(request.entity)
        response.state = self.state_of(request.entity)
        response.result = _result()

    def state_of(self, name, bodies=None):
        """EntityState of an entity now, ground truth in the world frame: its pose, its
        base's velocity and the mean acceleration over the last platform tick."""
        bodies = self.sim.entities() if bodies is None else bodies
        position, orientation = self.pose(name, bodies)
        _, _, linear, angular = self.sim.body_state(bodies[name])
        stamped = convert.pose(position, orientation, convert.stamp(self.sim.time))
        state = si.EntityState(header=stamped.header, pose=stamped.pose)
        state.twist.linear, state.twist.angular = _vector(linear), _vector(angular)
        state.acceleration.linear, state.acceleration.angular = map(
            _vector, self.accelerations.of(name))
        return state

    def tick(self):
        """Each platform tick: every movable entity's velocity, for the accelerations."""
        sim = self.sim
        self.accelerations.tick(sim.time, {name: sim.body_velocity(body)
                                           for name, body in sim.movers().items()})

    def _set_entity_state(self, request, response):
        entity = self.entity(request.entity)
        state = request.state
        invalid = srv.SetEntityState.Response.INVALID_POSE
        position, orientation = self._world_pose(state.header.frame_id, state.pose, invalid)
        linear, angular = check_twist(_values(state.twist.linear), _values(state.twist.angular),
                                      invalid)
        if entity.category == EntityCategory.STATIC_OBJECT:
            raise Refused(Result.OPERATION_FAILED, f'{entity.name} is static: it does not move')
        if entity.name in self.sim.robots:
            check_room(self.sim, entity.name, invalid, robot_at=(position, yaw_of(*orientation)))
        self.sim.set_object_pose(entity.name, position, orientation)
        if entity.name not in self.sim.robots:  # a robot's wheels say how it moves
            self.sim.set_body_velocity(self.sim.entities()[entity.name], linear, angular)
        response.result = _result()

    def _world_pose(self, frame_id, pose, code):
        """A request's pose in frame ``frame_id``, checked (check_pose), in the world frame:
        checked again there (an entity's frame may carry it out of bounds)."""
        frame = self._frame(frame_id)
        return check_pose(*in_world(frame, check_pose(*_pose_tuple(pose), code=code)),
                          code=code)

    def _frame(self, frame_id):
        """The world pose of a request's frame: the world, or an entity's."""
        if frame_id in WORLD_FRAMES:
            return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)
        self.entity(frame_id)
        return self.pose(frame_id)

    def _get_info(self, request, response):
        entity = self.entity(request.entity)
        response.info = si.EntityInfo(category=si.EntityCategory(category=entity.category),
                                      description=entity.description, tags=list(entity.tags))
        response.result = _result()

    def _set_info(self, request, response):
        entity = self.entity(request.entity)
        info = request.info
        if info.category.category not in codes.CATEGORIES:
            raise Refused(Result.OPERATION_FAILED, f'no entity category '
                                                   f'{info.category.category}')
        self.info[entity.name] = dataclasses.replace(
            entity, category=info.category.category, description=info.description[:1000],
            tags=tuple(tag[:64] for tag in info.tags[:32]))
        response.result = _result()

    def _get_bounds(self, request, response):
        self.entity(request.entity)
        body = self.sim.built_from(request.entity)
        response.bounds = _bounds(*(ROBOT_BOUNDS if body is None else entity_bounds(body)))
        response.result = _result()

    # -- spawning and deleting ----------------------------------------------------------------
    def _spawn_entity(self, request, response):
        response.entity_name = self.spawn(request)
        response.result = _result()

    def _spawn_entities(self, request, response):
        if len(request.spawn_requests) > MAX_SPAWNS:
            raise Refused(Result.OPERATION_FAILED, f'{len(request.spawn_requests)} entities '
                          f'asked for at once; at most {MAX_SPAWNS} a request')
        # Reading a text takes about a second a megabyte, and the world waits meanwhile.
        text = sum(len(one.entity_resource.resource_string) for one in request.spawn_requests)
        if text > MAX_RESOURCE_BYTES:
            raise Refused(Result.OPERATION_FAILED, f'{text} characters of resource_string in '
                          f'one request; at most {MAX_RESOURCE_BYTES} in all')
        failed = 0
        for one in request.spawn_requests:
            result = si.SpawnResult(result=_result())
            try:
                result.entity_name = self.spawn(one, resource=one.entity_resource)
            except Refused as refused:
                failed += 1
                self._warn('control:spawn', f'spawn_entities: {refused}')
                result.result = _result(refused.code, str(refused))
            response.results.append(result)
        response.result = _result() if not failed else _result(
            srv.SpawnEntities.Response.ENTITIES_SPAWN_FAILED,
            f'{failed} of {len(request.spawn_requests)} entities not spawned: see results')

    def spawn(self, request, resource=None):
        """Spawn what one request (SpawnEntity's or a SpawnEntity message) asks; its name."""
        self._need_world()
        resource = resource or request
        sim = self.sim
        # Every name get_entities lists is taken: 'wall_3' (a world's unnamed wall) too.
        spawn = parse_spawn(request.name, request.allow_renaming, resource.uri,
                            resource.resource_string, request.entity_namespace,
                            sim.names() | set(sim.entities()), self.host.world_folders)
        (x, y, z), orientation = self._world_pose(request.initial_pose.header.frame_id,
                                                  request.initial_pose.pose,
                                                  codes.SpawnResult.INVALID_POSE)
        spawn_at(sim, spawn, (x, y, z), yaw_of(*orientation))
        if not isinstance(spawn, RobotSpawn) and (spawn.description or spawn.tags):
            base = default_entity(spawn.name, self.sim.built_from(spawn.name))
            self.info[spawn.name] = dataclasses.replace(
                base, description=spawn.description or base.description,
                tags=spawn.tags or base.tags)
        self.host.world_changed()
        what = 'MiRo-E' if isinstance(spawn, RobotSpawn) else 'the ball' \
            if isinstance(spawn.body, Ball) else f'a {spawn.body.kind}'
        self.host.said('spawn', f'spawned {spawn.name} ({what}) at ({x:.3f}, {y:.3f}, {z:.3f})')
        return spawn.name

    def _delete(self, request, response):
        self._need_world()
        self.entity(request.entity)
        try:
            self.sim.remove(request.entity)
        except ValueError as err:  # the ground
            raise Refused(Result.OPERATION_FAILED, str(err)) from None
        self.info.pop(request.entity, None)
        self.host.world_changed()
        self.host.said('delete', f'deleted {request.entity}')
        response.result = _result()

    def forget(self):
        """The world was reset or another loaded: what was said about its entities goes."""
        self.info.clear()
        self.accelerations.forget()

    # -- named poses, spawnables, worlds ------------------------------------------------------
    def _named_poses(self, request, response):
        self._need_world()
        keep = tag_filter(list(request.tags.tags), request.tags.filter_mode)
        for pose in named_poses(self.sim.description, self.host.robot_name):
            if keep(pose.tags):
                msg = si.NamedPose(name=pose.name, description=pose.description,
                                   tags=list(pose.tags))
                msg.pose = convert.pose(pose.position, yaw_quaternion(pose.yaw),
                                        convert.stamp(0.0)).pose
                response.poses.append(msg)
        response.result = _result()

    def _named_pose_bounds(self, request, response):
        raise Refused(Result.FEATURE_UNSUPPORTED, 'named poses have no bounds here: a '
                      'named pose is a point and a heading')

    def _spawnables(self, request, response):
        if list(request.sources):
            raise Refused(Result.FEATURE_UNSUPPORTED, 'spawnables come from the bundled '
                          'models only (no other sources); any file:// or package:// '
                          'URDF or TOML can still be spawned')
        response.spawnables = [si.Spawnable(uri=uri, description=description,
                                            spawn_bounds=_bounds(*bounds))
                               for uri, description, bounds in spawnables()]
        response.result = _result()

    def _worlds(self, request, response):
        try:
            worlds, problems = world_catalogue(
                list(request.additional_sources), self.host.world_folders,
                self.host.sound_folders, self._world_cache)
        except ValueError as err:  # too many sources, or too long
            raise Refused(Result.OPERATION_FAILED, str(err)) from None
        if problems and not request.continue_on_error:
            raise Refused(Result.OPERATION_FAILED, problems[0])
        keep = tag_filter(list(request.filter.tags), request.filter.filter_mode)
        response.worlds = [_world_resource(name, uri, description, tags)
                           for name, uri, description, tags in worlds if keep(tags)]
        response.result = _result(Result.OK, '; '.join(problems)[:2000])

    def _current_world(self, request, response):
        if self.host.state == codes.SimulationState.NO_WORLD:
            raise Refused(srv.GetCurrentWorld.Response.NO_WORLD_LOADED, 'no world is loaded')
        world = self.sim.loaded
        response.world = _world_resource(world.name, self.host.world_uri, world.description,
                                         world.tags)
        response.result = _result()

    def _load_world(self, request, response):
        if self.host.state == codes.SimulationState.LOADING_WORLD:
            raise Refused(Result.INCORRECT_STATE, 'a world is loading already')
        try:
            if request.uri:
                world = load_world(request.uri, self.host.sound_folders,
                                   self.host.world_folders)
                uri = request.uri
            elif request.resource_string:
                world = parse_world(request.resource_string, 'resource_string',
                                    self.host.sound_folders, self.host.world_folders)
                uri = ''
            else:
                raise Refused(codes.LoadWorld.NO_RESOURCE,
                              "give a uri (a bundled world, a file) or a resource_string (a "
                              "world file's text)")
        except WorldError as err:
            raise Refused(LOAD_CODES[err.kind], f'{err} (the current world stays loaded)') \
                from None
        self.host.load(world, uri)
        response.world = _world_resource(world.name, uri, world.description, world.tags)
        response.result = _result()

    def _unload_world(self, request, response):
        if self.host.state == codes.SimulationState.NO_WORLD:
            raise Refused(srv.UnloadWorld.Response.NO_WORLD_LOADED, 'no world is loaded')
        self.host.unload()
        response.result = _result()


def _vector(values):
    x, y, z = (float(v) for v in values)
    return Vector3(x=x, y=y, z=z)


def _values(vector):
    return (vector.x, vector.y, vector.z)


def _pose_tuple(pose):
    p, q = pose.position, pose.orientation
    return (p.x, p.y, p.z), (q.x, q.y, q.z, q.w)


def _bounds(kind, points):
    return si.Bounds(type=kind, points=[_vector(p) for p in points])


def _world_resource(name, uri, description, tags):
    return si.WorldResource(name=name, world_resource=si.Resource(uri=uri),
                            description=description, tags=list(tags))
