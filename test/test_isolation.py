"""Each run claims ROS domains that no other process of ours on the machine holds."""
import subprocess
import sys

from miro_ball.common.isolation import private_domain, private_domains

CLAIM = 'import sys; from miro_ball.common import isolation; print(isolation._claim({}))'


def test_domains_are_distinct_and_held_against_other_processes():
    mine = [private_domain()] + private_domains(3, salt=7)
    assert len(set(mine)) == 4 and all(1 <= d <= 100 for d in mine)
    for domain in mine[:2]:
        other = subprocess.run([sys.executable, '-c', CLAIM.format(domain)],
                               capture_output=True, text=True, check=True, timeout=60)
        assert other.stdout.strip() == 'False', f'another process claimed domain {domain}'
