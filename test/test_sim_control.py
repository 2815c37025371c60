"""The pure logic behind the standard simulation_interfaces services: result codes, entity
filters, spawn requests, state transitions, and the world file's tags, poses and catalogue."""
import math
import os
import re
from dataclasses import replace
from importlib.resources import files

import pytest
from hypothesis import given, settings, strategies as st

from miro_ball.common.files import allowed_path, folders_parameter, read_regular
from miro_ball.miro.urdf import urdf
from miro_sim_bullet.control import codes
from miro_sim_bullet.control.accelerations import Accelerations, STILL
from miro_sim_bullet.control.codes import (Bounds, EntityCategory, Refused, SimulationState,
                                           SpawnResult, TagsFilter)
from miro_sim_bullet.control.entities import Entity, entity_bounds, entity_filter, ROBOT_BOUNDS
from miro_sim_bullet.control.placement import placed, reach
from miro_sim_bullet.control.posix_regex import compile_ere, MAX_PATTERN, MAX_STATES
from miro_sim_bullet.control.spawning import (parse_spawn, resolve_uri, RobotSpawn,
                                              ShapeSpawn, SPAWNABLE_MIRO, spawnables)
from miro_sim_bullet.control.states import transition
from miro_sim_bullet.scene.world_catalogue import world_catalogue, WorldCache
from miro_sim_bullet.scene.world_checks import parse_world
from miro_sim_bullet.scene.world_file import bundled_worlds, load_world
from miro_sim_bullet.scene.world_model import Ball, named_poses, Shape, WorldError

BOX_URI = 'package://miro_ball/worlds/models/box.toml'
BALL_URI = 'package://miro_ball/worlds/models/ball.toml'
EVERYWHERE = (Bounds.EMPTY, [])


def refused(call, *args):
    with pytest.raises(Refused) as caught:
        call(*args)
    assert '\n' not in str(caught.value) and str(caught.value)
    return caught.value


# -- codes ------------------------------------------------------------------------------
def test_every_code_is_the_built_standards_number():
    from simulation_interfaces import msg, srv
    pairs = {codes.Result: (msg.Result, 'RESULT_'), codes.SpawnResult: (msg.SpawnResult, ''),
             codes.EntityCategory: (msg.EntityCategory, 'CATEGORY_'),
             codes.SimulationState: (msg.SimulationState, 'STATE_'),
             codes.SetSimulationState: (srv.SetSimulationState.Response, ''),
             codes.TagsFilter: (msg.TagsFilter, 'FILTER_MODE_'),
             codes.Bounds: (msg.Bounds, 'TYPE_'), codes.LoadWorld: (srv.LoadWorld.Response, ''),
             codes.GetAvailableWorlds: (srv.GetAvailableWorlds.Response, '')}
    for ours, (theirs, prefix) in pairs.items():
        names = [n for n in vars(ours) if n.isupper()]
        assert names
        for name in names:
            assert getattr(ours, name) == getattr(theirs, prefix + name), (ours, name)
    for name in vars(codes.SpawnResult):
        if name.isupper():
            assert getattr(srv.SpawnEntity.Response, name) == getattr(codes.SpawnResult, name)


def test_a_refusal_is_one_line_with_its_code():
    error = Refused(SpawnResult.NAME_INVALID, 'bad\nname')
    assert (error.code, str(error)) == (SpawnResult.NAME_INVALID, 'bad name')


# -- entities ---------------------------------------------------------------------------
MIRO = Entity('miro02', EntityCategory.ROBOT, tags=('miro',))
BALL = Entity('ball', EntityCategory.DYNAMIC_OBJECT, tags=('ball',))
WALL = Entity('wall3', EntityCategory.STATIC_OBJECT)
ALL = (MIRO, BALL, WALL)


def kept(pattern='', categories=(), tags=(), mode=TagsFilter.ANY, bounds=EVERYWHERE,
         position=(0.0, 0.0, 0.0)):
    keep = entity_filter(pattern, list(categories), list(tags), mode, bounds)
    return [e.name for e in ALL if keep(e, position)]


def test_the_name_filter_is_a_posix_extended_search():
    assert kept() == ['miro02', 'ball', 'wall3']
    assert kept('iro') == ['miro02']  # searched, not matched whole
    assert kept('^(ball|wall)') == ['ball', 'wall3']
    assert kept('[[:digit:]]$') == ['miro02', 'wall3']
    assert kept('^miro$') == []


@pytest.mark.parametrize('pattern', ['x(', '[abc', r'\d', 'a*?', '(?i)miro', 'a' * 300,
                                     '[[:nope:]]'])
def test_a_pattern_that_is_no_posix_extended_expression_is_refused(pattern):
    error = refused(entity_filter, pattern, [], [], TagsFilter.ANY, EVERYWHERE)
    assert error.code == codes.Result.OPERATION_FAILED and 'filter' in str(error)


def test_a_filter_whose_automaton_would_be_big_is_refused():
    """'(.?){990}Q' made an automaton of 1982 states: each is looked at once a character of
    every name, and a name cost 155 times what it cost with 'a'. Counted repetition may not
    take an expression past as many states as a pattern has characters at most."""
    for pattern in ('(.?){990}Q', 'x{300}', '((a?){20}){20}', '[a-z]{0,900}Q'):
        error = refused(entity_filter, pattern, [], [], TagsFilter.ANY, EVERYWHERE)
        assert 'too complex' in str(error) and '\n' not in str(error), pattern
    biggest = compile_ere('^(.?){126}Q$')
    assert len(biggest.states) <= MAX_STATES == MAX_PATTERN
    assert biggest.search('x' * 126 + 'Q') and not biggest.search('x' * 127 + 'Q')


def test_categories_keep_any_of_those_given_and_unknown_ones_are_refused():
    assert kept(categories=[EntityCategory.ROBOT, EntityCategory.STATIC_OBJECT]) == \
        ['miro02', 'wall3']
    assert kept(categories=[EntityCategory.HUMAN]) == []
    assert refused(entity_filter, '', [3], [], 0, EVERYWHERE).code == \
        codes.Result.OPERATION_FAILED


def test_tags_any_keeps_one_with_some_all_one_with_every_tag():
    keep = entity_filter('', [], ['miro', 'ball'], TagsFilter.ANY, EVERYWHERE)
    assert [e.name for e in ALL if keep(e, (0, 0, 0))] == ['miro02', 'ball']
    both = Entity('x', 0, tags=('miro', 'ball', 'toy'))
    keep = entity_filter('', [], ['miro', 'ball'], TagsFilter.ALL, EVERYWHERE)
    assert [keep(e, (0, 0, 0)) for e in (MIRO, both)] == [False, True]
    assert refused(entity_filter, '', [], ['miro'], 2, EVERYWHERE).code == \
        codes.Result.OPERATION_FAILED


def test_sphere_bounds_keep_positions_within_the_radius_of_the_centre():
    sphere = (Bounds.SPHERE, [(1.0, 0.0, 0.0), (0.5, 99.0, 99.0)])  # y, z of the 2nd: unused
    assert kept(bounds=sphere, position=(1.4, 0.0, 0.0)) == ['miro02', 'ball', 'wall3']
    assert kept(bounds=sphere, position=(1.0, 0.6, 0.0)) == []


def test_box_bounds_keep_positions_between_the_corners_in_either_order():
    for corners in ([(1, 1, 1), (-1, -1, 0)], [(-1, -1, 0), (1, 1, 1)]):
        box = (Bounds.BOX, corners)
        assert len(kept(bounds=box, position=(0.5, -0.5, 0.0))) == 3
        assert kept(bounds=box, position=(0.5, -0.5, -0.1)) == []


@pytest.mark.parametrize('bounds, code', [
    ((Bounds.CONVEX_HULL, [(0, 0, 0), (1, 0, 0), (0, 1, 0)]), codes.Result.FEATURE_UNSUPPORTED),
    ((Bounds.SPHERE, [(0, 0, 0)]), codes.Result.OPERATION_FAILED),
    ((Bounds.BOX, [(0, 0, 0), (1, math.nan, 0)]), codes.Result.OPERATION_FAILED),
    ((Bounds.SPHERE, [(0, 0, 0), (-1, 0, 0)]), codes.Result.OPERATION_FAILED),
    ((Bounds.EMPTY, [(0, 0, 0)]), codes.Result.OPERATION_FAILED),
    ((9, []), codes.Result.OPERATION_FAILED)])
def test_bounds_that_cannot_be_applied_are_refused(bounds, code):
    assert refused(entity_filter, '', [], [], 0, bounds).code == code


def test_entity_bounds_are_the_standards_shapes_round_the_origin():
    away = (3.0, -2.0, 1.0)  # a shape's bounds are in its own frame, wherever it is
    assert entity_bounds(Shape('sphere', away, radius=0.1)) == \
        (Bounds.SPHERE, [(0, 0, 0), (0.1, 0, 0)])
    assert entity_bounds(Ball((1.0, 2.0), 0.1, 0.4, (0, 0, 1), 0.5, 0.5)) == \
        (Bounds.SPHERE, [(0, 0, 0), (0.1, 0, 0)])
    assert entity_bounds(Shape('box', away, yaw=1.0, size=(0.2, 0.4, 0.6))) == \
        (Bounds.BOX, [(0.1, 0.2, 0.3), (-0.1, -0.2, -0.3)])
    assert entity_bounds(Shape('cylinder', away, radius=0.05, length=0.2)) == \
        (Bounds.BOX, [(0.05, 0.05, 0.1), (-0.05, -0.05, -0.1)])
    kind, (upper, lower) = ROBOT_BOUNDS
    assert kind == Bounds.BOX and lower[2] == 0.0 and upper[2] > 0.25  # on the floor, upright


def test_an_acceleration_is_the_mean_over_the_last_platform_tick():
    accelerations = Accelerations()
    accelerations.tick(0.0, {'ball': ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))})
    assert accelerations.of('ball') == STILL  # one tick seen: nothing to difference
    accelerations.tick(0.02, {'ball': ((0.1, 0.0, -0.2), (0.0, 0.0, 0.1)), 'miro': STILL})
    linear, angular = accelerations.of('ball')
    assert linear == pytest.approx((5.0, 0.0, -10.0)) and angular == pytest.approx((0, 0, 5.0))
    assert accelerations.of('miro') == STILL and accelerations.of('nobody') == STILL
    accelerations.tick(0.04, {'miro': STILL})  # the ball deleted: forgotten
    assert accelerations.of('ball') == STILL
    accelerations.forget()
    accelerations.tick(0.06, {'miro': ((1.0, 0.0, 0.0), (0.0, 0.0, 0.0))})
    assert accelerations.of('miro') == STILL  # nothing before a reset counts


# -- spawning ---------------------------------------------------------------------------
def spawn(name='', renaming=False, uri='', text='', namespace='', taken=(), folders=()):
    return parse_spawn(name, renaming, uri, text, namespace, set(taken), folders)


def spawn_code(**request):
    return refused(spawn, *[request.get(k, d) for k, d in (
        ('name', ''), ('renaming', False), ('uri', ''), ('text', ''), ('namespace', ''),
        ('taken', ()), ('folders', ()))]).code


def test_our_urdf_spawns_a_miro_by_text_or_uri():
    assert spawn('miro04', text=urdf()) == RobotSpawn('miro04')
    assert spawn('miro04', uri=SPAWNABLE_MIRO) == RobotSpawn('miro04')


def test_another_robots_urdf_or_other_xml_is_refused_and_garbage_does_not_parse():
    other = '<robot name="r2d2"><link name="base_link"/><link name="dome"/></robot>'
    assert spawn_code(name='r', text=other) == SpawnResult.UNSUPPORTED_ASSETS
    assert spawn_code(name='r', text='<sdf version="1.9"/>') == SpawnResult.UNSUPPORTED_FORMAT
    assert spawn_code(name='r', text='<robot name="x">') == SpawnResult.RESOURCE_PARSE_ERROR
    assert spawn_code(name='r', uri='file:///tmp/model.sdf') == SpawnResult.UNSUPPORTED_FORMAT


def test_a_toml_table_spawns_a_box_or_the_ball():
    box = spawn('crate', text='[box]\nsize = [0.2, 0.2, 0.2]\nmass = 0.5')
    assert isinstance(box, ShapeSpawn) and box.name == box.body.name == 'crate'
    assert (box.body.kind, box.body.mass) == ('box', 0.5)
    ball = spawn(uri=BALL_URI)
    assert isinstance(ball.body, Ball) and ball.name == 'ball' and ball.tags == ('ball', 'toy')
    assert spawn_code(uri=BALL_URI, taken={'ball'}) == SpawnResult.NAME_NOT_UNIQUE
    static = spawn('post', text='[[cylinder]]\nradius = 0.1\nlength = 1.0')
    assert static.body.mass == 0 and static.name == 'post'  # named though static


@pytest.mark.parametrize('text', [
    '[[box]]\nsize = [1, 1, 1]\n[[box]]\nsize = [1, 1, 1]',  # two entities
    '[box]\nsize = [1, 1, 1]\n[ball]',
    '[box]\nsize = [1, 1, -1]',  # a bad key, as a world file says it
    'not = toml = at all', '[robot]\npose = [0, 0, 0]', 'x = 1'])
def test_a_toml_that_is_not_one_good_entity_is_a_parse_error(text):
    assert spawn_code(name='x', text=text) == SpawnResult.RESOURCE_PARSE_ERROR


def test_names_are_renamed_when_allowed_else_refused():
    assert spawn(renaming=True, uri=BOX_URI, taken={'box1'}).name == 'box2'
    assert spawn(renaming=True, uri=SPAWNABLE_MIRO, taken={'miro'}).name == 'miro1'
    assert spawn('crate', True, uri=BOX_URI, taken={'crate', 'crate_1'}).name == 'crate_2'
    assert spawn_code(name='crate', uri=BOX_URI, taken={'crate'}) == SpawnResult.NAME_NOT_UNIQUE
    assert spawn_code(uri=BOX_URI) == SpawnResult.NAME_INVALID  # no name, no renaming
    for bad in ('2fast', 'a-b', '/miro', 'ball', 'x' * 200):
        assert spawn_code(name=bad, uri=BOX_URI) == SpawnResult.NAME_INVALID, bad
        assert spawn_code(name=bad, uri=SPAWNABLE_MIRO) == SpawnResult.NAME_INVALID, bad


def test_a_miros_namespace_is_its_name_and_a_shape_has_none():
    assert spawn('miro05', uri=SPAWNABLE_MIRO, namespace='/miro05').name == 'miro05'
    assert spawn('miro05', uri=SPAWNABLE_MIRO, namespace='miro05').name == 'miro05'
    assert spawn(uri=SPAWNABLE_MIRO, namespace='/miro06').name == 'miro06'
    for namespace in ('/other', '/a/b', '/2x'):
        assert spawn_code(name='miro05', uri=SPAWNABLE_MIRO, namespace=namespace) == \
            SpawnResult.NAMESPACE_INVALID
    # A MiRo asked for in a taken namespace is not moved elsewhere by renaming.
    assert spawn_code(renaming=True, uri=SPAWNABLE_MIRO, namespace='/miro',
                      taken={'miro'}) == SpawnResult.NAME_NOT_UNIQUE
    assert spawn_code(name='crate', uri=BOX_URI, namespace='/crate') == \
        SpawnResult.NAMESPACE_INVALID


def test_every_spawnable_resolves_and_spawns_with_its_bounds():
    listed = spawnables()
    assert [uri for uri, _, _ in listed][:1] == [SPAWNABLE_MIRO]
    assert {BOX_URI, BALL_URI} <= {uri for uri, _, _ in listed}
    for uri, description, (kind, points) in listed:
        text, _ = resolve_uri(uri)
        assert text and description and kind in (Bounds.BOX, Bounds.SPHERE) and len(points) == 2
        made = spawn(renaming=True, uri=uri)
        assert isinstance(made, RobotSpawn if uri.endswith('.urdf') else ShapeSpawn)


def test_a_missing_file_or_package_is_no_resource(tmp_path):
    for uri in (str(tmp_path / 'none.toml'), f'file://{tmp_path}/none.urdf',
                'package://miro_ball/worlds/models/none.toml', 'package://no_such_pkg/a.urdf',
                'relative/box.toml', 'package://miro_ball/worlds/../../x.toml'):
        assert spawn_code(name='x', uri=uri) == SpawnResult.NO_RESOURCE, uri
    assert spawn_code() == SpawnResult.NO_RESOURCE  # neither uri nor text


def test_a_file_of_ones_own_spawns_and_a_huge_one_is_refused(tmp_path):
    mine = tmp_path / 'crate.toml'
    mine.write_text('description = "my crate"\n[box]\nsize = [0.3, 0.3, 0.3]\nmass = 1.0\n')
    folders = (tmp_path.resolve(),)  # the simulator's world_folders
    made = spawn('crate', uri=f'file://{mine}', folders=folders)
    assert (made.description, made.body.size) == ('my crate', (0.3, 0.3, 0.3))
    assert spawn('crate', uri=str(mine), folders=folders).name == 'crate'
    assert spawn_code(name='crate', uri=str(mine)) == SpawnResult.NO_RESOURCE  # not allowed
    mine.write_text('# ' + 'x' * 2_000_000)
    assert spawn_code(name='crate', uri=str(mine), folders=folders) == \
        SpawnResult.RESOURCE_PARSE_ERROR


def test_the_uri_is_used_when_both_uri_and_text_are_given():
    made = parse_spawn('miro09', False, SPAWNABLE_MIRO, '[box]\nsize = [1, 1, 1]', '', set())
    assert made == RobotSpawn('miro09')


@settings(max_examples=150, deadline=None)
@given(name=st.text(max_size=12), renaming=st.booleans(),
       uri=st.one_of(st.just(''), st.text(max_size=30), st.sampled_from([
           BOX_URI, SPAWNABLE_MIRO, 'package://miro_ball/x/../../a.toml', 'file:///a.urdf',
           'package://../x.urdf', '/\x00.toml'])),
       text=st.one_of(st.text(max_size=200), st.sampled_from([
           urdf()[:5000], '[box]\nsize = [1, 1, 1]', '[ball]\nradius = 0.1',
           '<robot name="x"><link name="a"/></robot>'])),
       namespace=st.text(max_size=8), taken=st.sets(st.sampled_from(['ball', 'box1', 'x'])))
def test_garbage_requests_are_refused_never_crash(name, renaming, uri, text, namespace, taken):
    try:
        made = parse_spawn(name, renaming, uri, text, namespace, taken)
    except Refused as error:
        assert error.code in range(101, 110) and '\n' not in str(error)
    else:
        assert made.name and made.name not in taken


def test_a_spawned_body_asked_for_below_its_floor_stands_on_it():
    ball = Ball((0.0, 0.0), 0.1, 0.4, (0, 0, 1), 0.5, 0.5, floor=0.2)
    assert placed(ball, (1.0, 2.0, 0.0), 1.0, ground=0.0) == replace(ball, position=(1.0, 2.0))
    assert placed(ball, (1.0, 2.0, 0.5), 1.0, ground=0.0).floor == pytest.approx(0.4)
    box = Shape('box', (0.0, 0.0, 0.0), size=(0.2, 0.2, 0.4), mass=1.0)
    low = placed(box, (1.0, 2.0, -3.0), 0.5, ground=0.1)
    assert low.position == pytest.approx((1.0, 2.0, 0.3)) and low.yaw == 0.5
    assert placed(box, (1.0, 2.0, 0.9), 0.5, ground=0.1).position == (1.0, 2.0, 0.9)
    cylinder = Shape('cylinder', (0.0, 0.0, 0.0), radius=0.1, length=0.6)
    assert placed(cylinder, (0.0, 0.0, 0.0), 0.0, ground=0.0).position[2] == pytest.approx(0.3)
    low, high = reach(low)  # the box round it, a centimetre in on every side
    assert (low[2], high[2]) == pytest.approx((0.11, 0.49))


# -- states -----------------------------------------------------------------------------
S = SimulationState


@pytest.mark.parametrize('current, target, action', [
    (S.PLAYING, S.PAUSED, 'pause'), (S.PAUSED, S.PLAYING, 'play'),
    (S.PLAYING, S.STOPPED, 'stop'), (S.PAUSED, S.STOPPED, 'stop'),
    (S.STOPPED, S.PLAYING, 'play'), (S.PLAYING, S.QUITTING, 'quit'),
    (S.NO_WORLD, S.QUITTING, 'quit')])
def test_the_transitions_the_standard_allows(current, target, action):
    assert transition(current, target) == action


@pytest.mark.parametrize('current, target, code', [
    (S.PAUSED, S.PAUSED, codes.SetSimulationState.ALREADY_IN_TARGET_STATE),
    (S.STOPPED, S.PAUSED, codes.SetSimulationState.INCORRECT_TRANSITION),
    (S.PLAYING, S.NO_WORLD, codes.SetSimulationState.INCORRECT_TRANSITION),
    (S.PLAYING, S.LOADING_WORLD, codes.SetSimulationState.INCORRECT_TRANSITION),
    (S.PLAYING, 42, codes.SetSimulationState.INCORRECT_TRANSITION),
    (S.NO_WORLD, S.PLAYING, codes.SetSimulationState.STATE_TRANSITION_ERROR),
    (S.LOADING_WORLD, S.PAUSED, codes.SetSimulationState.STATE_TRANSITION_ERROR),
    (S.QUITTING, S.PLAYING, codes.SetSimulationState.STATE_TRANSITION_ERROR)])
def test_the_transitions_it_refuses(current, target, code):
    assert refused(transition, current, target).code == code


def test_no_world_says_to_load_one():
    assert 'load_world' in str(refused(transition, S.NO_WORLD, S.PLAYING))


# -- world files: tags, poses, catalogue -------------------------------------------------
def write(tmp_path, text, name='mine.toml'):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_a_world_has_tags_and_its_placements_and_declared_poses_are_named(tmp_path):
    world = load_world(write(tmp_path, '''
tags = ["practice", "ball"]
[[robot]]
name = "miro01"
pose = [1.0, 2.0, 0.5]
floor = 0.25
[[robot]]
name = "miro02"
[ball]
position = [0.5, 0.0]
radius = 0.1
[[pose]]
name = "goal"
position = [1.5, 0.0]
yaw = 3.0
description = "in front of the goal"
tags = ["football"]
'''))
    assert world.tags == ('practice', 'ball')
    poses = {pose.name: pose for pose in named_poses(world, 'unused')}
    assert list(poses) == ['miro01_start', 'miro02_start', 'ball_start', 'goal']
    assert (poses['miro01_start'].position, poses['miro01_start'].yaw) == ((1.0, 2.0, 0.25), 0.5)
    assert poses['ball_start'].position == (0.5, 0.0, 0.1)  # the ball's centre
    assert 'start' in poses['ball_start'].tags
    goal = poses['goal']
    assert (goal.position, goal.yaw, goal.tags) == ((1.5, 0.0, 0.0), 3.0, ('football',))


def test_a_single_unnamed_robots_start_takes_the_name_given():
    assert named_poses(load_world('t_maze'), 'miro02')[0].name == 'miro02_start'


@pytest.mark.parametrize('text, key', [
    ('tags = "ball"', 'tags'), ('tags = [1]', 'tags'), (f'tags = {["t"] * 33}', 'tags'),
    ('[[pose]]\nposition = [0, 0]', "missing 'name'"),
    ('[[pose]]\nname = "2x"', 'pose[0].name'),
    ('[[pose]]\nname = "a"\n[[pose]]\nname = "a"', 'pose[1].name'),
    ('[[pose]]\nname = "miro_start"', 'pose[0].name'),
    ('[[pose]]\nname = "a"\nposition = [0]', 'pose[0].position'),
    ('[[pose]]\nname = "a"\nyaw = nan', 'pose[0].yaw'),
    ('[[pose]]\nname = "a"\ncolour = [1, 1, 1]', "unknown key 'colour'")])
def test_bad_tags_and_poses_say_which_key(tmp_path, text, key):
    with pytest.raises(WorldError, match=key.replace('[', r'\[').replace(']', r'\]')):
        load_world(write(tmp_path, text))


def test_every_bundled_world_has_a_description_and_tags():
    for name in bundled_worlds():
        world = load_world(name)
        assert world.description and world.tags, name
    assert {'centre_spot', 'east_end', 'west_end'} <= \
        {pose.name for pose in load_world('football_pitch').poses}
    assert {'left_arm_end', 'right_arm_end'} <= {pose.name for pose in load_world('t_maze').poses}


def test_the_catalogue_lists_bundled_worlds_and_a_folders_good_files(tmp_path):
    allowed = (tmp_path.resolve(),)
    write(tmp_path, 'description = "mine"\ntags = ["x"]\n', 'good.toml')
    write(tmp_path, '[ball]\nradius = -1\n', 'bad.toml')
    write(tmp_path, 'not a world', 'notes.txt')
    worlds, problems = world_catalogue([str(tmp_path), str(tmp_path / 'none')], allowed)
    by_name = {name: (uri, description, tags) for name, uri, description, tags in worlds}
    assert set(bundled_worlds()) | {'good'} == set(by_name)
    assert by_name['good'] == (str(tmp_path / 'good.toml'), 'mine', ('x',))
    assert by_name['miro'][0] == 'package://miro_ball/worlds/miro.toml'
    assert load_world(by_name['miro'][0]).name == 'miro'  # the uri loads
    assert len(problems) == 2 and 'not a folder' in problems[0] and 'bad.toml' in problems[1]


SECRET = 'AKIA-PLANTED-SECRET'


@pytest.fixture
def private(tmp_path):
    """(a folder the simulator was started with, a folder it was not) with world files and
    config files holding SECRET in both."""
    allowed, elsewhere = tmp_path / 'worlds', tmp_path / 'private'
    for folder in (allowed, elsewhere):
        folder.mkdir()
        write(folder, f'description = "{SECRET}"\n', 'world.toml')
        write(folder, f'[ball]\nradius = "{SECRET}"\n', 'config.toml')
    return allowed.resolve(), elsewhere


def test_the_catalogue_lists_only_the_allowed_folders_and_never_quotes_another(private):
    allowed, elsewhere = private
    spelt = [str(elsewhere), f'{elsewhere}/', f'{allowed}/../private', f'file://{elsewhere}',
             '/etc', '~', str(allowed / '..')]
    worlds, problems = world_catalogue(spelt, (allowed,))
    assert set(bundled_worlds()) == {name for name, *_ in worlds}
    assert len(problems) == len(spelt) and SECRET not in ' '.join(problems)
    assert all('not a folder the simulator may list' in line for line in problems)
    (elsewhere / 'link').symlink_to(allowed)  # a link into an allowed folder is that folder
    worlds, problems = world_catalogue([str(allowed), f'{allowed}//./', str(elsewhere / 'link'),
                                        f'{allowed}/../worlds'], (allowed,))
    assert [name for name, *_ in worlds].count('world') == 1 and len(problems) == 1


def test_the_catalogue_refuses_too_many_sources_and_reads_within_its_time(tmp_path):
    """2,187 spellings of one folder held the simulator for 71 s; a folder of many worlds
    is read a part at a time, each part within the budget, and what was read is kept."""
    with pytest.raises(ValueError, match='at most 16 sources'):
        world_catalogue(['worlds/'] * 17)
    with pytest.raises(ValueError, match='at most 16 sources'):
        world_catalogue(['x' * 5000])
    for k in range(30):
        write(tmp_path, f'description = "w{k}"\n', f'w{k:02}.toml')
    ticks = iter(range(10**6))
    clock = lambda: next(ticks) * 0.1  # every look at the clock: 0.1 s later
    cache, read = WorldCache(), set()
    for _ in range(30):
        worlds, problems = world_catalogue([str(tmp_path)], (tmp_path.resolve(),),
                                           cache=cache, budget_s=1.0, clock=clock)
        read |= {name for name, *_ in worlds if name.startswith('w')}
        if not problems:
            break
        assert problems == [problems[0]] and 'not read within 1 s' in problems[0]
    assert len(read) == 30 and not problems


def test_a_world_a_client_names_is_bundled_or_in_the_allowed_folders(private):
    allowed, elsewhere = private
    assert load_world(str(allowed / 'world.toml'), (), (allowed,)).description == SECRET
    assert load_world('world.toml', (), (allowed,)).description == SECRET  # relative: looked for
    assert load_world('den', (), (allowed,)).name == 'den'
    lines = set()
    for name in ('world.toml', 'config.toml', 'missing.toml', 'folder.toml'):
        (elsewhere / 'folder.toml').mkdir(exist_ok=True)
        for spelt in (str(elsewhere / name), f'file://{elsewhere}/{name}',
                      f'{allowed}/../private/{name}'):
            with pytest.raises(WorldError) as err:
                load_world(spelt, (), (allowed,))
            assert SECRET not in str(err.value)
            lines.add(re.sub("'.*?' in", "'NAME' in", str(err.value), count=1))
    assert lines == {"no world file 'NAME' in the allowed folders: a bundled world ("
                     f"{', '.join(bundled_worlds())}), or a .toml file in a folder the "
                     'simulator was started with (its world_folders parameter)'}
    (allowed / 'pipe.toml').unlink(missing_ok=True)
    os.mkfifo(allowed / 'pipe.toml')
    with pytest.raises(WorldError, match='no world file'):
        load_world(str(allowed / 'pipe.toml'), (), (allowed,))


def test_a_picture_is_bundled_beside_the_world_or_in_the_allowed_folders(private):
    allowed, elsewhere = private
    picture = allowed / 'mine.png'
    picture.write_bytes((files('miro_sim_bullet.worlds') / 'pictures' / 'face_photo.png')
                        .read_bytes())
    (elsewhere / 'secret.png').write_bytes(picture.read_bytes())
    (elsewhere / 'notes.png').write_text(SECRET)
    box = '[[box]]\nsize = [1, 1, 1]\npicture = "{}"\n'
    assert parse_world(box.format(picture), 'resource_string', (), (allowed,)).pictures
    assert parse_world(box.format('face_photo.png'), 'resource_string').pictures
    lines = set()
    for name in ('secret.png', 'notes.png', 'missing.png'):
        for spelt in (str(elsewhere / name), f'{allowed}/../private/{name}'):
            with pytest.raises(WorldError) as err:
                parse_world(box.format(spelt), 'resource_string', (), (allowed,))
            lines.add(re.sub("'.*?' in", "'NAME' in", str(err.value), count=1))
    assert len(lines) == 1 and SECRET not in lines.pop()
    with pytest.raises(WorldError, match='no picture'):  # a world's own folder, not others'
        load_world(write(allowed, box.format(elsewhere / 'secret.png'), 'framed.toml'))


def test_a_name_of_a_user_there_is_none_of_is_refused_as_any_other(private):
    """~nosuchuser raised RuntimeError: answered 'a bug', it told which accounts exist."""
    allowed, _ = private
    for name in ('~nosuchuser/x.toml', '~root/x.toml'):
        assert allowed_path(name, (allowed,)) is None
        with pytest.raises(WorldError, match='no world file'):
            load_world(name, (), (allowed,))
    with pytest.raises(ValueError, match="parameter world_folders: '~nosuchuser' is not a"):
        folders_parameter('world_folders', '~nosuchuser')


def test_a_file_is_read_through_no_link_on_its_way(private):
    """A folder swapped for a link between the check and the read led out of the allowed
    folders: every part of the path is opened without following a link."""
    allowed, elsewhere = private
    (allowed / 'sub').symlink_to(elsewhere)
    for path in (allowed / 'sub' / 'world.toml', allowed / 'sub' / '..' / 'world.toml'):
        with pytest.raises(OSError):
            read_regular(path, 100)
    assert SECRET.encode() in read_regular(elsewhere / 'world.toml', 100)


def test_the_catalogue_says_the_rule_for_a_link_out_whatever_it_points_at(private):
    allowed, elsewhere = private
    (allowed / 'out.toml').symlink_to(elsewhere / 'world.toml')
    (allowed / 'dangling.toml').symlink_to(elsewhere / 'missing.toml')
    (allowed / 'loop.toml').symlink_to(allowed / 'loop.toml')
    (allowed / 'in.toml').symlink_to(allowed / 'world.toml')
    os.mkfifo(allowed / 'pipe.toml')
    (allowed / 'caf\udce9.toml'.encode('utf-8', 'surrogateescape').decode(
        'utf-8', 'surrogateescape')).write_text('description = "x"\n')
    worlds, problems = world_catalogue([str(allowed)], (allowed,))
    listed = {name: uri for name, uri, *_ in worlds}
    assert listed['in'] == str(allowed / 'world.toml')  # by its resolved path
    lines = {re.sub("'.*?' in", "'NAME' in", line, count=1) for line in problems
             if any(k in line for k in ('out', 'dangling', 'loop', 'caf'))}
    assert lines == {"no world file 'NAME' in the allowed folders"}, problems
    assert any('pipe.toml' in line for line in problems) and 'pipe' not in listed
    '\n'.join(problems).encode('utf-8')  # every line can be sent


def test_a_description_is_bounded(tmp_path):
    """get_available_worlds answers 1000 descriptions at once."""
    with pytest.raises(WorldError, match='description: must be a string of at most 4096'):
        load_world(write(tmp_path, f'description = "{"x" * 4097}"\n'))


def test_a_model_a_client_names_is_in_its_package_or_in_the_allowed_folders(private):
    allowed, elsewhere = private
    write(allowed, '[[box]]\nsize = [0.1, 0.1, 0.1]\n', 'crate.toml')
    assert 'size' in resolve_uri(str(allowed / 'crate.toml'), (allowed,))[0]
    assert 'size' in resolve_uri(f'file://{allowed}/crate.toml', (allowed,))[0]
    lines = set()
    for uri in (str(elsewhere / 'config.toml'), str(elsewhere / 'missing.toml'),
                f'{allowed}/../private/config.toml', 'package://miro_ball/../../etc/x.toml',
                'package://miro_ball//etc/x.toml', 'package://miro_ball/worlds/../../x.toml',
                'package://miro_ball/test/x.toml', 'package://no_such_package/x.toml'):
        caught = refused(resolve_uri, uri, (allowed,))
        assert caught.code == SpawnResult.NO_RESOURCE and SECRET not in str(caught)
        lines.add(re.sub("'.*?':", "'NAME':", str(caught), count=1))
    assert len(lines) == 1, lines


def test_a_bundled_worlds_uri_resolves_and_a_models_is_no_world():
    assert 'face_board' in resolve_uri('package://miro_ball/worlds/den.toml')[0]
    with pytest.raises(WorldError, match='unknown world'):
        load_world('package://miro_ball/worlds/models/box.toml')
