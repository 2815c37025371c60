"""SetSimulationState's table: what a request to go from one state to another does.

  from \\ to     PLAYING   PAUSED    STOPPED   QUITTING
  PLAYING       already   pause     stop      quit
  PAUSED        play      already   stop      quit
  STOPPED       play      refused   already   quit
  NO_WORLD      no world  no world  no world  quit
  LOADING_WORLD loading   loading   loading   quit
  QUITTING      quitting  quitting  quitting  already

'stop' is a reset and a pause (the world back at its start, time still); STOPPED ->
PLAYING plays from there. 'already' is ALREADY_IN_TARGET_STATE; 'refused' is
INCORRECT_TRANSITION (pausing a stopped simulation, the standard's own example); 'no
world', 'loading' and 'quitting' are STATE_TRANSITION_ERROR. Asking for NO_WORLD or
LOADING_WORLD, or a state that does not exist, is INCORRECT_TRANSITION: only load_world
and unload_world lead there.
"""
from miro_sim_bullet.control.codes import (Refused, SetSimulationState, SimulationState,
                                           STATES)

_ACTIONS = {
    (SimulationState.PLAYING, SimulationState.PAUSED): 'pause',
    (SimulationState.PLAYING, SimulationState.STOPPED): 'stop',
    (SimulationState.PAUSED, SimulationState.PLAYING): 'play',
    (SimulationState.PAUSED, SimulationState.STOPPED): 'stop',
    (SimulationState.STOPPED, SimulationState.PLAYING): 'play',
}
_SETTABLE = (SimulationState.PLAYING, SimulationState.PAUSED, SimulationState.STOPPED,
             SimulationState.QUITTING)


def transition(current, target):
    """'play', 'pause', 'stop' or 'quit' (a clean exit) to go from ``current`` to
    ``target`` (codes.SimulationState), or Refused with SetSimulationState's code."""
    if target not in _SETTABLE:
        settable = ', '.join(f'{state} ({STATES[state]})' for state in _SETTABLE)
        raise Refused(SetSimulationState.INCORRECT_TRANSITION,
                      f'state {target!r} cannot be asked for: ask for {settable} '
                      '(load_world and unload_world change the world)')
    if current == target:
        raise Refused(SetSimulationState.ALREADY_IN_TARGET_STATE,
                      f'the simulation is {STATES[target]} already')
    if target == SimulationState.QUITTING:
        return 'quit'
    if (current, target) in _ACTIONS:
        return _ACTIONS[current, target]
    if current == SimulationState.STOPPED:  # to PAUSED
        raise Refused(SetSimulationState.INCORRECT_TRANSITION,
                      'a stopped simulation cannot be paused: play it, then pause it')
    problem = {SimulationState.NO_WORLD: 'no world is loaded: load_world first',
               SimulationState.LOADING_WORLD: 'a world is loading: wait for load_world',
               SimulationState.QUITTING: 'the simulator is quitting'}
    raise Refused(SetSimulationState.STATE_TRANSITION_ERROR,
                  problem.get(current, f'the simulation is in an unknown state {current!r}'))
