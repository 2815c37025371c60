"""The layering rules, in one place: who may import whom.

- Our modules stand on FLOORS (docs/development.md's Layering): a module imports only from
  its own floor and those below it, never up.
- The simulator loads no controller, GUI, example or lab code (nodes talk only over ROS).
- MiRo's own library (miro_ball.miro), demo mode's parts and the simulator's control logic
  (miro_sim_bullet.control) import neither rclpy nor PyBullet; the trained-policy
  controller (miro_ball.policy) neither Gymnasium nor PyBullet.
- No import cycles between our modules, counting imports inside functions too (a cycle
  hidden in a function is still a cycle).
"""
import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ('miro_ball', 'miro_sim_bullet')
# What the simulator may use of miro_ball: MiRo's facts and the shared plumbing.
SIMULATOR_MAY_USE = ('miro_ball.miro', 'miro_ball.common')
# The floors, from the ground up (docs/development.md, Layering): a package or module of
# ours and everything in it stands on one floor.
FLOORS = (
    ('miro_ball.miro',),  # what MiRo is: its numbers, body, interface, readers
    ('miro_ball.common',),  # what every node needs
    # The simulator, and the nodes, parts and clients that talk to it over ROS.
    ('miro_sim_bullet', 'miro_ball.controller', 'miro_ball.policy', 'miro_ball.animal',
     'miro_ball.robot', 'miro_ball.examples', 'miro_ball.mapping', 'miro_ball.gui',
     'miro_ball.recording', 'miro_ball.record', 'miro_ball.ros2', 'miro_ball.foxglove',
     'miro_ball.build_interfaces', 'miro_ball.__main__'),
    # What runs them together: episodes and processes, the grader, learning, launch files,
    # the lab tools, the benchmarks.
    ('miro_ball.run', 'miro_ball.grading', 'miro_ball.learn', 'miro_ball.launch',
     'miro_ball.lab', 'miro_ball.grade', 'miro_ball.bench'),
)


def our_modules():
    """{dotted name: path} of every module of our packages."""
    found = {}
    for package in PACKAGES:
        for path in (ROOT / package).rglob('*.py'):
            parts = path.relative_to(ROOT).with_suffix('').parts
            if parts[-1] == '__init__':
                parts = parts[:-1]
            found['.'.join(parts)] = path
    return found


def imports_of(name, path, modules):
    """Our modules that module `name` imports anywhere in its text."""
    package = name if path.name == '__init__.py' else name.rpartition('.')[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ''
            if node.level:
                base = '.'.join(package.split('.')[:len(package.split('.')) - node.level + 1]
                                + ([base] if base else []))
            # `from a.b import c` uses a.b, or the module a.b.c if there is one.
            targets = [f'{base}.{alias.name}' if f'{base}.{alias.name}' in modules else base
                       for alias in node.names]
        else:
            continue
        found.update(t for t in targets if t in modules and t != name)
    return found


def loaded_by(module):
    """The modules of ours that importing `module` loads, from a clean interpreter."""
    code = (f'import sys, {module}\n'
            'print("\\n".join(sorted(sys.modules)))')
    done = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                          timeout=120, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    return set(done.stdout.split())


def floor_of(module):
    """The floor ``module`` stands on (0: the ground), or None if FLOORS places it nowhere."""
    for number, rooms in enumerate(FLOORS):
        if any(module == room or module.startswith(room + '.') for room in rooms):
            return number
    return None


def test_every_module_stands_on_a_floor_and_imports_nothing_above_it():
    """miro.readers, on the ground floor, once imported common.checks from the floor above."""
    modules = our_modules()
    # The packages themselves hold no code: each module imports them on its way.
    placed = {name: floor_of(name) for name in modules if name not in PACKAGES}
    assert not [name for name, floor in placed.items() if floor is None], \
        'put these in a floor of FLOORS (and docs/development.md): ' + \
        ', '.join(sorted(name for name, floor in placed.items() if floor is None))
    upwards = [f'{name} (floor {floor}) imports {target} (floor {placed[target]})'
               for name, floor in sorted(placed.items())
               for target in sorted(imports_of(name, modules[name], modules))
               if target in placed and placed[target] > floor]
    assert not upwards, '\n'.join(upwards)


def test_our_modules_import_in_no_cycle():
    modules = our_modules()
    graph = {name: imports_of(name, path, modules) for name, path in modules.items()}
    # A package imports its __init__ on the way to a submodule: that is not a cycle.
    for name in graph:
        graph[name] = {t for t in graph[name] if not name.startswith(t + '.')}
    done, cycles = set(), []

    def visit(name, trail):
        if name in trail:
            cycles.append(trail[trail.index(name):] + [name])
            return
        if name in done:
            return
        for target in sorted(graph[name]):
            visit(target, trail + [name])
        done.add(name)

    for name in sorted(graph):
        visit(name, [])
    assert not cycles, '\n'.join(' -> '.join(cycle) for cycle in cycles)


def test_the_simulator_loads_no_controller_gui_or_lab_code():
    simulator = sorted(m for m in our_modules()
                       if m.startswith('miro_sim_bullet') and not m.endswith('__main__'))
    ours = {m for m in loaded_by(', '.join(simulator)) if m.split('.')[0] == 'miro_ball'}
    foreign = {m for m in ours - {'miro_ball'} if m not in SIMULATOR_MAY_USE
               and not m.startswith(tuple(p + '.' for p in SIMULATOR_MAY_USE))}
    assert not foreign, sorted(foreign)


def test_miros_own_library_needs_neither_ros_nor_pybullet():
    library = sorted(m for m in our_modules() if m.startswith('miro_ball.miro'))
    loaded = loaded_by(', '.join(library))
    assert not {m.split('.')[0] for m in loaded} & {'rclpy', 'pybullet'}


def test_demo_modes_parts_need_neither_ros_nor_pybullet():
    # The animal's parts are plain Python with time passed in: tested, and reused, alone
    # (demo_mode and core_topics are its ROS side: the host's kind and its topics).
    parts = sorted(m for m in our_modules() if m.startswith('miro_ball.animal.')
                   and m.rsplit('.', 1)[1] not in ('demo_mode', 'core_topics', '__main__'))
    assert 'miro_ball.animal.animal' in parts
    loaded = loaded_by(', '.join(parts))
    assert not {m.split('.')[0] for m in loaded} & {'rclpy', 'pybullet'}


def test_the_simulators_control_logic_needs_neither_ros_nor_pybullet():
    # What a request to the standard services means (filters, spawn requests, the state
    # table, poses) is decided in plain Python, tested alone; sim_control is its ROS side.
    logic = sorted(m for m in our_modules() if m.startswith('miro_sim_bullet.control.'))
    assert 'miro_sim_bullet.control.spawning' in logic
    loaded = loaded_by(', '.join(logic))
    assert not {m.split('.')[0] for m in loaded} & {'rclpy', 'pybullet', 'simulation_interfaces'}


def test_the_learning_environments_need_no_ros_and_nothing_else_needs_gymnasium():
    # In-process learning: no rclpy, no DDS. And the nodes, which never learn, do not pay
    # Gymnasium's import (0.13 s a start).
    learning = sorted(m for m in our_modules() if m.startswith('miro_ball.learn.'))
    assert 'miro_ball.learn.env' in learning
    assert 'rclpy' not in {m.split('.')[0] for m in loaded_by(', '.join(learning))}
    nodes = ('miro_sim_bullet.ros.node, miro_ball.controller.host, miro_ball.gui.server, '
             'miro_ball.lab, miro_ball.grade')
    assert 'gymnasium' not in {m.split('.')[0] for m in loaded_by(nodes)}


def test_the_policy_controller_loads_neither_gymnasium_nor_pybullet():
    """A controller node running a trained policy once loaded both (0.6 s a start): the
    policy read the sonar's range from the simulator's physics, and lived in miro_ball.learn,
    whose package registers its environments with Gymnasium."""
    loaded = loaded_by('miro_ball.policy.controller')
    assert 'miro_ball.policy.controller' in loaded
    assert not {m.split('.')[0] for m in loaded} & {'gymnasium', 'pybullet'}


def _private_methods(cls_node):
    return {item.name for item in cls_node.body
            if isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef))
            and item.name.startswith('_') and not item.name.endswith('__')}


def test_no_class_overrides_another_modules_private_methods():
    """A private method is its module's own business: a class in another module that
    replaces one (as demo mode's node once replaced the controller node's _declare,
    _apply, _on_tick, ...) couples two modules through what neither promised. Our own base
    classes only; a public hook, or a part handed in, is the way."""
    modules = our_modules()
    classes = {}  # (module, class name): (the class's AST, [(base module, base name)])
    for name, path in modules.items():
        tree = ast.parse(path.read_text(), str(path))
        imported = {}
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module in modules:
                for alias in node.names:  # a class, or a module (from package import mod)
                    module = f'{node.module}.{alias.name}'
                    imported[alias.asname or alias.name] = \
                        (module, None) if module in modules else (node.module, alias.name)
            elif isinstance(node, ast.Import):
                imported.update({alias.asname or alias.name: (alias.name, None)
                                 for alias in node.names if alias.name in modules})
        for node in tree.body:
            if not isinstance(node, ast.ClassDef):
                continue
            bases = []
            for base in node.bases:
                if isinstance(base, ast.Name):
                    bases.append(imported.get(base.id, (name, base.id)))
                elif isinstance(base, ast.Attribute) and isinstance(base.value, ast.Name) \
                        and base.value.id in imported:
                    bases.append((imported[base.value.id][0], base.attr))
            classes[(name, node.name)] = (node, bases)
    assert len(classes) > 100  # the scan found our classes
    overrides = []
    for (module, cls), (node, bases) in classes.items():
        for base in bases:
            if base[0] == module or base not in classes:
                continue
            shared = _private_methods(node) & _private_methods(classes[base][0])
            overrides += [f'{module}.{cls}.{method} replaces {base[0]}.{base[1]}.{method}'
                          for method in sorted(shared)]
    assert not overrides, '\n'.join(overrides)
