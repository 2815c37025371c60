"""SharedVectorEnv: several learning environments stepped at once, one process a core, the
calling process stepping its share itself.

Gymnasium's AsyncVectorEnv keeps the caller idle while its workers step, and sends every
step's actions and results through a pipe per environment: on a state-only step of about
1 ms that made 1.14x one process on two cores. Here the environments are split into one
group a process (by default a process a usable core, the caller's own one of them): the
caller sends each worker its group's actions (one short message, which is its wake-up),
steps its own group meanwhile, then takes each worker's reply (rewards, ends and infos:
small). Every process writes its observations straight into the batch's shared memory, so
no image crosses a pipe.

Gymnasium 1.x's conventions: ``autoreset_mode`` NEXT_STEP by default (an environment that
ended is reset at the next step, that step's action for it ignored, its reward 0), SAME_STEP
and DISABLED as its own vector envs do them (``metadata['autoreset_mode']`` says which);
``reset(seed=s)`` seeds environment k with s + k (a list: a seed each); ``copy=True``
returns observations the next step does not overwrite; ``call``, ``get_attr``, ``set_attr``
and ``render`` as Gymnasium's own give them. Each environment is the same as one
alone: the same seeds and actions give the same episodes, bit for bit (tested).

Workers are started fresh (multiprocessing's 'spawn': no renderer, thread or world of the
caller is inherited), ignore Ctrl+C (the caller stops them) and end when close() tells them,
when the caller's end of their pipe closes, or when the caller is gone: nothing is left
behind. An environment's error (an action it refuses) comes back as that error, naming the
environment; the others have stepped.

    from miro_ball.learn.vector import make_vec
    envs = make_vec('miro_ball/KickBall-v0', num_envs=2, eyes=None)

or ``gymnasium.make_vec('miro_ball/KickBall-v0', num_envs=2,
vectorization_mode='vector_entry_point')``. How fast: python -m miro_ball.bench.learn_bench.
"""
import functools
import multiprocessing
import os
import pickle
import signal
import time
from multiprocessing.reduction import ForkingPickler

import gymnasium
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import (CloudpickleWrapper, batch_space, create_shared_memory,
                                    iterate, read_from_shared_memory)

from miro_ball.learn.core import check_count

# About 56 MB a state-only world: 128 of them are 7 GB, more than a learner here would want.
MAX_ENVS = 128
PARENT_CHECK_S = 1.0  # how often an idle worker looks whether its caller is still there
# How long a process that waits for the other side looks before it sleeps. A partner most
# often answers within a fraction of a step, and waking a process that slept costs it its
# core's caches and (on this VM) a wake-up's latency: state only on 2 free cores, 1.56-1.59x
# one process where sleeping at once gave 1.29-1.58x (A/B in turns); with no core free, no
# worse (0.73-0.86x both), as each look gives the core to anyone else who wants it.
SPIN_S = 0.0002
JOIN_S = 5.0  # close(): how long a worker may take to end before it is killed


def usable_cores():
    return len(os.sched_getaffinity(0))


def answered(conn, within_s):
    """Whether ``conn`` has something to read within ``within_s``: looking all the while,
    the core given to anyone else who wants it at each look (sched_yield)."""
    end = time.perf_counter() + within_s
    while not conn.poll(0):
        if time.perf_counter() >= end:
            return False
        os.sched_yield()
    return True


def split(count, parts):
    """``count`` environment indices in ``parts`` contiguous groups, the first the largest."""
    size, extra = divmod(count, parts)
    groups, start = [], 0
    for part in range(parts):
        end = start + size + (part < extra)
        groups.append(range(start, end))
        start = end
    return groups


def put(batch, index, value):
    """Write ``value`` (one environment's observation) at ``index`` of ``batch`` (the
    observations' arrays, as read_from_shared_memory gives them: views made once, where
    Gymnasium's write_to_shared_memory makes them anew at every write)."""
    if isinstance(batch, dict):
        for key, part in batch.items():
            put(part, index, value[key])
    elif isinstance(batch, tuple):
        for part, each in zip(batch, value):
            put(part, index, each)
    else:
        batch[index] = value


def copied(batch):
    """The observations' arrays, copied (deepcopy took 3 times as long)."""
    if isinstance(batch, dict):
        return {key: copied(part) for key, part in batch.items()}
    if isinstance(batch, tuple):
        return tuple(copied(part) for part in batch)
    return batch.copy()


class Group:
    """The environments one process steps (indices ``first`` on), each with whether its
    last step ended its episode (for the autoreset), writing their observations into the
    batch's shared memory."""

    def __init__(self, envs, first, autoreset_mode, space, shared, count):
        self.envs, self.first = envs, first
        self.autoreset_mode = autoreset_mode
        self.batch = read_from_shared_memory(space, shared, count)
        self.ended = [False] * len(envs)

    def reset(self, seeds, options, mask):
        """[(index, info or the error)] of the environments ``mask`` picks."""
        out = []
        for k, env in enumerate(self.envs):
            index = self.first + k
            if not mask[index]:
                continue
            try:
                observation, info = env.reset(seed=seeds[index], options=options)
            except Exception as err:  # noqa: BLE001 (handed to the caller, who raises it)
                out.append((index, err))
                continue
            self.ended[k] = False
            put(self.batch, index, observation)
            out.append((index, info))
        return out

    def step(self, actions):
        """[(index, (reward, terminated, truncated, info)) or (index, the error)]."""
        out = []
        for k, (env, action) in enumerate(zip(self.envs, actions)):
            index = self.first + k
            try:
                result = self._step_one(k, env, action)
            except Exception as err:  # noqa: BLE001 (handed to the caller, who raises it)
                out.append((index, err))
                continue
            observation, reward, terminated, truncated, info = result
            self.ended[k] = bool(terminated or truncated)
            put(self.batch, index, observation)
            out.append((index, (reward, terminated, truncated, info)))
        return out

    def _step_one(self, k, env, action):
        mode = self.autoreset_mode
        if mode is AutoresetMode.NEXT_STEP and self.ended[k]:
            observation, info = env.reset()
            return observation, 0.0, False, False, info
        if mode is AutoresetMode.DISABLED and self.ended[k]:
            raise ValueError('its episode ended: reset it first (autoreset DISABLED: '
                             "reset(options={'reset_mask': ...}))")
        observation, reward, terminated, truncated, info = env.step(action)
        if mode is AutoresetMode.SAME_STEP and (terminated or truncated):
            final = {'final_obs': observation, 'final_info': info}
            observation, info = env.reset()
            info = {**final, **info}
        return observation, reward, terminated, truncated, info

    def call(self, name, args, kwargs):
        """[(index, each environment's attribute ``name``, called with ``args`` and
        ``kwargs`` if it is a method) or (index, the error)]."""
        def one(env, _):
            value = env.get_wrapper_attr(name)
            return value(*args, **kwargs) if callable(value) else value

        return self._each(one, [None] * len(self.envs))

    def set_attr(self, name, values):
        """Set each environment's attribute ``name`` to its value in ``values``."""
        return self._each(lambda env, value: env.set_wrapper_attr(name, value),
                          values[self.first:self.first + len(self.envs)])

    def _each(self, do, values):
        out = []
        for k, (env, value) in enumerate(zip(self.envs, values)):
            try:
                out.append((self.first + k, do(env, value)))
            except Exception as err:  # noqa: BLE001 (handed to the caller, who raises it)
                out.append((self.first + k, err))
        return out

    def close(self):
        for env in self.envs:
            env.close()


def _serve(conn, env_fns, first, autoreset_mode, space, shared, count, parent):
    """A worker's life: build its group, then answer the caller's commands until told to
    close, or the caller's end of the pipe closes, or the caller is gone."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl+C reaches the group: the caller stops us
    try:
        group = Group([fn.fn() for fn in env_fns], first, autoreset_mode, space, shared,
                      count)
    except Exception as err:  # noqa: BLE001 (the caller raises it)
        conn.send(('failed', err))
        return
    conn.send(('ready', [(env.observation_space, env.action_space) for env in group.envs]))
    try:
        while True:
            if not answered(conn, SPIN_S):
                while not conn.poll(PARENT_CHECK_S):
                    if os.getppid() != parent:
                        return
            command, argument = conn.recv()
            if command == 'close':
                return
            reply = getattr(group, command)(*argument)  # step, reset, call or set_attr
            try:
                conn.send(reply)
            except (pickle.PicklingError, TypeError, AttributeError) as err:  # what call() gave
                conn.send([(index, RuntimeError(f'its answer can not be sent: {err}'))
                           for index, _ in reply])
    except (EOFError, OSError, KeyboardInterrupt):
        return  # the caller is gone
    finally:
        group.close()


class SharedVectorEnv(VectorEnv):
    """The environments ``env_fns`` make (each a function of no arguments, as Gymnasium's
    vector envs take), stepped by ``processes`` processes (default: one a usable core, at
    most one an environment; the caller is one of them). ``autoreset_mode``: as Gymnasium's
    (default NEXT_STEP). ``copy``: observations of their own each call (False: views the
    next call overwrites). ``context``: how workers start (multiprocessing's; default
    'spawn')."""

    def __init__(self, env_fns, processes=None, autoreset_mode=AutoresetMode.NEXT_STEP,
                 copy=True, context='spawn'):
        self._workers = []  # (our end of its pipe, the process, its environments' indices)
        self._group = None  # the caller's own environments
        env_fns = list(env_fns)
        self.num_envs = count = check_count('num_envs', len(env_fns), MAX_ENVS)
        processes = min(count, usable_cores()) if processes is None else \
            check_count('processes', processes, count)
        self.autoreset_mode = AutoresetMode(autoreset_mode)  # ValueError naming a bad one
        ctx = multiprocessing.get_context(context)  # and a bad context, before any build
        self.copy = bool(copy)
        self.closed = False
        groups = split(count, processes)
        try:
            own = []
            for index in groups[0]:
                own.append(env_fns[index]())
            self.single_observation_space = own[0].observation_space
            self.single_action_space = own[0].action_space
            self._check_spaces((env.observation_space, env.action_space) for env in own)
            self.observation_space = batch_space(self.single_observation_space, count)
            self.action_space = batch_space(self.single_action_space, count)
            self.metadata = {**own[0].metadata, 'autoreset_mode': self.autoreset_mode}
            self.render_mode = own[0].render_mode
            shared = create_shared_memory(self.single_observation_space, count, ctx)
            self._group = Group(own, 0, self.autoreset_mode, self.single_observation_space,
                                shared, count)
            self._observations = self._group.batch
            self._start_workers(ctx, env_fns, groups[1:], shared)
        except BaseException:
            if self._group is None:
                for env in own:
                    env.close()
            self.close()
            raise
        self._rewards = np.zeros(count, np.float64)
        self._terminations = np.zeros(count, np.bool_)
        self._truncations = np.zeros(count, np.bool_)

    def _start_workers(self, ctx, env_fns, groups, shared):
        for group in groups:
            mine, theirs = ctx.Pipe()
            process = ctx.Process(
                target=_serve, daemon=True, name=f'SharedVectorEnv worker of {group}',
                args=(theirs, [CloudpickleWrapper(env_fns[i]) for i in group], group.start,
                      self.autoreset_mode, self.single_observation_space, shared,
                      self.num_envs, os.getpid()))
            process.start()
            theirs.close()  # the worker's end is its own: if it dies, our read ends (EOF)
            self._workers.append((mine, process, group))
        for worker, _, _ in self._workers:  # built side by side: now each says it is ready
            status, answer = self._receive(worker, starting=True)
            if status == 'failed':
                raise answer
            self._check_spaces(answer)

    def _check_spaces(self, spaces):
        """ValueError unless every (observation space, action space) of ``spaces`` is the
        first environment's (one process or several alike)."""
        if any(each != (self.single_observation_space, self.single_action_space)
               for each in spaces):
            raise ValueError('the environments do not all have the same spaces')

    @property
    def processes(self):
        """The worker processes (as Gymnasium's AsyncVectorEnv has them); the caller is not
        one of them."""
        return [process for _, process, _ in self._workers]

    # -- Gymnasium ----------------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        self._check_open()
        count = self.num_envs
        if seed is None:
            seeds = [None] * count
        elif isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
            seeds = [int(seed) + k for k in range(count)]
        else:
            seeds = list(seed) if isinstance(seed, (list, tuple)) else None
            if seeds is None or len(seeds) != count:
                raise ValueError(f'seed: None, a whole number or a list of {count}, '
                                 f'got {seed!r}')
        options = dict(options or {})
        mask = options.pop('reset_mask', None)
        if mask is None:
            mask = np.ones(count, np.bool_)
        elif not (isinstance(mask, np.ndarray) and mask.dtype == np.bool_
                  and mask.shape == (count,) and mask.any()):
            raise ValueError(f"options['reset_mask']: a numpy bool array of {count} with "
                             'one True at least')
        results = self._all([('reset', (seeds, options, mask))] * len(self._workers),
                            self._group.reset, seeds, options, mask)
        infos = {}
        for index, info in self._raise_any(results):
            self._terminations[index] = self._truncations[index] = False
            infos = self._add_info(infos, info, index)
        return self._observation_batch(), infos

    def step(self, actions):
        self._check_open()
        each = list(iterate(self.action_space, actions))
        if len(each) != self.num_envs:
            raise ValueError(f'actions: a batch of {self.num_envs}, got {len(each)}')
        results = self._all([('step', (each[group.start:group.stop],))
                             for _, _, group in self._workers],
                            self._group.step, each[:len(self._group.envs)])
        infos = {}
        for index, (reward, terminated, truncated, info) in self._raise_any(results):
            self._rewards[index] = reward
            self._terminations[index] = terminated
            self._truncations[index] = truncated
            infos = self._add_info(infos, info, index)
        return (self._observation_batch(), self._rewards.copy(), self._terminations.copy(),
                self._truncations.copy(), infos)

    def call(self, name, *args, **kwargs):
        """Each environment's attribute ``name``, called with ``args`` and ``kwargs`` if it
        is a method (a tuple, as Gymnasium's vector envs give it)."""
        self._check_open()
        results = self._all([('call', (name, args, kwargs))] * len(self._workers),
                            self._group.call, name, args, kwargs)
        return tuple(value for _, value in self._raise_any(results))

    def get_attr(self, name):
        return self.call(name)

    def set_attr(self, name, values):
        """Set each environment's attribute ``name``: to its item of ``values`` (a list or
        tuple of num_envs), or to ``values``."""
        self._check_open()
        if not isinstance(values, (list, tuple)):
            values = [values] * self.num_envs
        if len(values) != self.num_envs:
            raise ValueError(f'values: a list or tuple of {self.num_envs}, got {len(values)}')
        self._raise_any(self._all([('set_attr', (name, values))] * len(self._workers),
                                  self._group.set_attr, name, values))

    def render(self):
        """Each environment's render() (a tuple)."""
        return self.call('render')

    def close_extras(self, **kwargs):
        """Tell every worker to end, wait for it (at most JOIN_S, then kill it), and close
        this process's own environments. A second close() does nothing."""
        for worker, _, _ in self._workers:
            try:
                worker.send(('close', None))
            except OSError:
                pass  # already gone
        for worker, process, _ in self._workers:
            process.join(JOIN_S)
            if process.is_alive():
                process.kill()
                process.join()
            worker.close()
        self._workers = []
        if self._group is not None:
            self._group.close()

    def __del__(self):
        if not getattr(self, 'closed', True):
            self.close()

    # -- the parts ----------------------------------------------------------------------------
    def _check_open(self):
        if self.closed:
            raise gymnasium.error.ClosedEnvironmentError('this vector env is closed')

    def _send(self, worker, data):
        """Send a message pickled (``data``) to a worker."""
        try:
            worker.send_bytes(data)
        except OSError:  # a worker killed while we were away: its pipe is broken
            self._worker_ended()

    def _receive(self, worker, starting=False):
        answered(worker, SPIN_S)  # then a blocking read
        try:
            return worker.recv()
        except (EOFError, OSError):
            self._worker_ended(starting)

    def _worker_ended(self, starting=False):
        """Close (the other workers too: replies left unread would answer the next call) and
        raise one line with the workers' exit codes."""
        processes = self.processes
        self.close()  # joins them: each has its exit code
        codes = [process.exitcode for process in processes]
        # A worker starts fresh and imports the caller's script: one that makes a vector
        # env outside "if __name__ == '__main__':" makes another in each worker, which fails
        # (exit code 1). One killed by a signal (a negative code) was not that.
        raise RuntimeError(
            f'a worker of the vector env ended (exit codes {", ".join(map(str, codes))})' + (
                " before it was ready: make the vector env under if __name__ == "
                "'__main__': (its workers import the script)" if starting and 1 in codes
                else '')) from None

    def _all(self, messages, own, *arguments):
        """The results of every environment: each worker sent its message (``messages``, in
        the workers' order), our own group's (``own(*arguments)``), then each worker's
        reply."""
        # All pickled before any is sent: one that can not be (a value of set_attr) is its
        # error, and the workers have nothing to answer.
        pickled = [ForkingPickler.dumps(message) for message in messages]
        try:
            for (worker, _, _), data in zip(self._workers, pickled):
                self._send(worker, data)
            return own(*arguments) + self._gather()
        except BaseException:
            # Cut short (Ctrl+C), even between two sends: replies left unread would answer
            # the next call.
            self.close()
            raise

    def _gather(self):
        return [result for worker, _, _ in self._workers for result in self._receive(worker)]

    def _raise_any(self, results):
        """``results`` in the environments' order; the first error, naming its
        environment, raised once every result is in."""
        results = sorted(results, key=lambda result: result[0])
        for index, result in results:
            if isinstance(result, BaseException):
                try:  # the same kind of error (a ValueError for a refused action)
                    error = type(result)(f'environment {index}: {result}')
                except Exception:  # noqa: BLE001 (one whose class takes other arguments)
                    error = RuntimeError(f'environment {index}: {result!r}')
                raise error from result
        return results

    def _observation_batch(self):
        return copied(self._observations) if self.copy else self._observations


def _make_one(env_id, wrappers, kwargs):
    env = gymnasium.make(env_id, **kwargs)
    for wrapper in wrappers:
        env = wrapper(env)
    return env


def make_vec(env_id, num_envs, *, wrappers=(), processes=None,
             autoreset_mode=AutoresetMode.NEXT_STEP, copy=True, context='spawn', **kwargs):
    """``num_envs`` environments ``gymnasium.make(env_id, **kwargs)``, each in ``wrappers``
    (functions of an env, in order), as a SharedVectorEnv (its other keywords)."""
    count = check_count('num_envs', num_envs, MAX_ENVS)
    env_fn = functools.partial(_make_one, env_id, tuple(wrappers), kwargs)
    return SharedVectorEnv([env_fn] * count, processes=processes,
                           autoreset_mode=autoreset_mode, copy=copy, context=context)


def vector_entry_point(num_envs=1, task=None, **options):
    """What ``gymnasium.make_vec(id, vectorization_mode='vector_entry_point')`` calls: a
    SharedVectorEnv of the registered task's environments (learn.registry)."""
    from miro_ball.learn.registry import make

    count = check_count('num_envs', num_envs, MAX_ENVS)
    vector_options = {name: options.pop(name) for name in
                      ('processes', 'autoreset_mode', 'copy', 'context') if name in options}
    return SharedVectorEnv([functools.partial(make, task, **options)] * count,
                           **vector_options)
