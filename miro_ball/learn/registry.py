"""What each registered environment id makes (learn/__init__.py registers them)."""
from miro_ball.learn.env import MiroEnv
from miro_ball.learn.kbandit import Expressions, KBandit
from miro_ball.learn.t_maze import TMaze
from miro_ball.learn.tasks import KickBall


def kick_ball(limit_s=20.0, **kwargs):
    """miro_ball/KickBall-v0: lab 1, the ball detector's readings in the observation."""
    return MiroEnv(KickBall(limit_s=limit_s), **kwargs)


def k_bandit(trials=30, mistakes=0.1, eyes=None, **kwargs):
    """miro_ball/KBandit-v0: which expression does the person like? Discrete(4) actions."""
    return Expressions(MiroEnv(KBandit(trials=trials, mistakes=mistakes), eyes=eyes,
                               **kwargs))


def t_maze(limit_s=20.0, cue=True, arm=None, **kwargs):
    """miro_ball/TMaze-v0: up the stem and into the arm the ball marks (learn/t_maze.py)."""
    return MiroEnv(TMaze(limit_s=limit_s, cue=cue, arm=arm), **kwargs)
