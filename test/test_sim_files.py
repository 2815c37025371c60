"""The standard simulator services read no file outside the allowed folders: the bundled
worlds, models and pictures, and the folders the simulator was started with (world_folders).
Anything else is refused in one line that names the rule, the same line whether the file is
there or not, and never a word of what a file holds; the world steps on meanwhile."""
import re
from importlib.resources import files

import pytest
from simulation_interfaces import msg as si
from simulation_interfaces import srv

from test_sim_standard_hostile import FAILED, ok, pose, serve, still_works

SECRET = 'AKIA-PLANTED-SECRET'


@pytest.fixture
def folders(tmp_path):
    """(the simulator's world_folders, a private folder): each with a world, a config file
    and a picture holding SECRET."""
    allowed, private = tmp_path / 'worlds', tmp_path / 'private'
    png = (files('miro_sim_bullet.worlds') / 'pictures' / 'face_photo.png').read_bytes()
    for folder in (allowed, private):
        folder.mkdir()
        (folder / 'world.toml').write_text(f'description = "{SECRET}"\n[robot]\n')
        (folder / 'config.toml').write_text(f'[ball]\nradius = "{SECRET}"\n')
        (folder / 'crate.toml').write_text('[box]\nsize = [0.1, 0.1, 0.1]\nmass = 0.5\n')
        (folder / 'photo.png').write_bytes(png)
        (folder / 'notes.png').write_text(SECRET)
    return allowed, private


def one_line(message, name):
    """The refusal with the name it quotes taken out: what it says of the rule."""
    assert SECRET not in message and '\n' not in message, message
    return re.sub(r"'[^']*'", 'NAME', message, count=1).replace(name, 'NAME')


def the_refusal(node, kind, code, requests):
    """The one line (one_line) ``kind`` answers every request of ``requests`` (name ->
    the request's fields) with, each with result ``code``."""
    lines = set()
    for name, fields in requests.items():
        refused = serve(node, kind, **fields)
        assert refused.result.result == code, name
        lines.add(one_line(refused.result.error_message, name))
    assert len(lines) == 1, lines
    return lines.pop()


def test_the_catalogue_lists_the_allowed_folders_only(make_sim, folders):
    allowed, private = folders
    node = make_sim(world_folders=str(allowed))
    for sources in ([str(private)], [f'{allowed}/../private'], ['/etc'], ['~']):
        refused = serve(node, srv.GetAvailableWorlds, additional_sources=sources)
        assert refused.result.result == FAILED
        assert 'not a folder the simulator may list' in one_line(
            refused.result.error_message, sources[0])
        listed = ok(serve(node, srv.GetAvailableWorlds, additional_sources=sources,
                          continue_on_error=True))
        assert SECRET not in str(listed) and 'world' not in {w.name for w in listed.worlds}
    listed = ok(serve(node, srv.GetAvailableWorlds, additional_sources=[str(allowed)],
                      continue_on_error=True))
    assert {'miro', 'world'} <= {w.name for w in listed.worlds}
    still_works(node)


def test_a_flood_of_spellings_of_one_folder_is_refused_at_once(make_sim, folders):
    """2,187 spellings of worlds/ (74 kB) stopped /clock for 71 s."""
    allowed, _ = folders
    node = make_sim(world_folders=str(allowed))
    spelt = [str(allowed) + '/.' * k for k in range(2187)]
    refused = serve(node, srv.GetAvailableWorlds, additional_sources=spelt)
    assert refused.result.result == FAILED
    assert 'at most 16 sources' in refused.result.error_message
    listed = ok(serve(node, srv.GetAvailableWorlds, additional_sources=spelt[:16],
                      continue_on_error=True))
    assert [w.name for w in listed.worlds].count('world') == 1  # each folder once
    still_works(node)


def test_load_world_reads_no_file_outside_and_says_the_same_whatever_is_there(make_sim,
                                                                              folders):
    allowed, private = folders
    node = make_sim(world_folders=str(allowed))
    uris = (str(private / 'world.toml'), str(private / 'config.toml'),
            str(private / 'missing.toml'), f'file://{private}/world.toml',
            f'{allowed}/../private/config.toml', '/etc/shadow', '/etc/passwd')
    assert 'world_folders' in the_refusal(node, srv.LoadWorld, srv.LoadWorld.Response.NO_RESOURCE,
                                          {uri: {'uri': uri} for uri in uris})
    assert ok(serve(node, srv.GetCurrentWorld)).world.name == 'miro'  # stays loaded
    assert ok(serve(node, srv.LoadWorld, uri='world.toml')).world.name == 'world'
    still_works(node)


def test_a_load_errors_code_is_its_kind_not_its_words(make_sim, folders):
    """A file that breaks a rule is RESOURCE_PARSE_ERROR even when its name reads like a
    missing one (the code was told by 'unknown world' or 'no world file' in the message)."""
    allowed, _ = folders
    node = make_sim(world_folders=str(allowed))
    (allowed / 'no world file.toml').write_text('[robot]\npose = "unknown world"\n')
    refused = serve(node, srv.LoadWorld, uri=str(allowed / 'no world file.toml'))
    assert refused.result.result == srv.LoadWorld.Response.RESOURCE_PARSE_ERROR
    assert 'robot.pose' in refused.result.error_message
    missing = serve(node, srv.LoadWorld, uri='package://miro_ball/worlds/nowhere.toml')
    assert missing.result.result == srv.LoadWorld.Response.NO_RESOURCE
    assert ok(serve(node, srv.GetCurrentWorld)).world.name == 'miro'  # stays loaded
    still_works(node)


def test_a_worlds_picture_is_no_window_onto_other_files(make_sim, folders):
    """A box's picture = "/absolute/path.png" hung any PNG on a wall, in MiRo's eyes."""
    allowed, private = folders
    node = make_sim(world_folders=str(allowed))
    box = '[robot]\n[[box]]\nsize = [1, 1, 1]\nposition = [2, 0, 0.5]\npicture = "{}"\n'
    pictures = (private / 'photo.png', private / 'notes.png', private / 'missing.png',
                f'{allowed}/../private/photo.png')
    assert 'no picture' in the_refusal(
        node, srv.LoadWorld, srv.LoadWorld.Response.RESOURCE_PARSE_ERROR,
        {str(picture): {'resource_string': box.format(picture)} for picture in pictures})
    assert ok(serve(node, srv.LoadWorld, resource_string=box.format(allowed / 'photo.png')))
    assert node.sim.loaded.pictures
    still_works(node)


def test_spawn_entity_reads_models_from_packages_and_the_allowed_folders_only(make_sim,
                                                                               folders):
    allowed, private = folders
    node = make_sim(world_folders=str(allowed))
    uris = (str(private / 'crate.toml'), str(private / 'missing.toml'),
            f'file://{private}/config.toml', 'package://miro_ball//etc/passwd.toml',
            'package://miro_ball/../../../etc/x.toml')
    assert 'world_folders' in the_refusal(
        node, srv.SpawnEntity, srv.SpawnEntity.Response.NO_RESOURCE,
        {uri: {'name': 'crate', 'uri': uri, 'initial_pose': pose(1.0, 1.0)} for uri in uris})
    ok(serve(node, srv.SpawnEntity, name='crate', uri=str(allowed / 'crate.toml'),
             initial_pose=pose(1.0, 1.0)))
    assert 'crate' in still_works(node)


def test_a_world_folder_that_is_no_folder_stops_the_start(make_sim, tmp_path):
    with pytest.raises(ValueError, match="parameter world_folders: '.*none' is not a folder"):
        make_sim(world_folders=str(tmp_path / 'none'))



def test_spawn_entities_reads_at_most_a_megabyte_of_text_a_request(paused_sim):
    """64 entities of 1 MB of TOML each held the simulator for about a minute."""
    node = paused_sim
    text = '[box]\nsize = [0.1, 0.1, 0.1]\n' + '#' * 400_000 + '\n'
    requests = [si.SpawnEntity(name=f'box{k}', entity_resource=si.Resource(resource_string=text),
                               initial_pose=pose(1.0, 0.3 * k)) for k in range(3)]
    refused = serve(node, srv.SpawnEntities, spawn_requests=requests)
    assert refused.result.result == FAILED
    assert 'at most 1048576 in all' in refused.result.error_message
    assert ok(serve(node, srv.SpawnEntities, spawn_requests=requests[:2]))
    assert {'box0', 'box1'} <= set(still_works(node))
