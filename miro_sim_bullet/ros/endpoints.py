"""Where the simulator's interfaces make their publishers, subscriptions and services."""
from dataclasses import dataclass, field
from typing import Callable


@dataclass(frozen=True)
class Endpoints:
    """The create_* functions of the node that owns the endpoints (rclpy's signatures):
    an interface made with these needs nothing else of the node. Those of owned() also
    keep what they made, so that destroy() takes it all down again (a robot deleted, a
    world unloaded while the node runs on)."""

    publisher: Callable
    subscription: Callable
    service: Callable
    timer: Callable
    destroy_publisher: Callable = None  # of a publisher no longer wanted (an object gone)
    made: list = field(default=None, compare=False)
    destroy: Callable = field(default=None, compare=False)

    @classmethod
    def of(cls, node):
        return cls(node.create_publisher, node.create_subscription, node.create_service,
                   node.create_timer, node.destroy_publisher)

    @classmethod
    def owned(cls, node):
        made = []

        def keeping(create, destroy):
            def make(*args, **kwargs):
                endpoint = create(*args, **kwargs)
                made.append((destroy, endpoint))
                return endpoint
            return make

        def destroy_all():
            while made:
                destroy, endpoint = made.pop()
                destroy(endpoint)

        return cls(keeping(node.create_publisher, node.destroy_publisher),
                   keeping(node.create_subscription, node.destroy_subscription),
                   keeping(node.create_service, node.destroy_service),
                   keeping(node.create_timer, node.destroy_timer), node.destroy_publisher,
                   made, destroy_all)


def send_if_listened(publisher, build):
    """Publish build() only if someone subscribes (a message nobody receives costs ~25 us
    to build and publish, a look at the subscription count 1.4 us) and it is not None;
    whether it was published."""
    if publisher.get_subscription_count():
        msg = build()
        if msg is not None:
            publisher.publish(msg)
            return True
    return False
