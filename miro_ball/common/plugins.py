"""A class named on the command line: a built-in name, or ``package.module:Class`` of a
user's own (a controller's mode, demo mode's action selector)."""
import importlib


def named_class(parameter, value, built_in, method, kind):
    """The class ``value`` names (a key of built_in, whose values are 'module:Class', or
    'module:Class'), which must have ``method``; ValueError in one line otherwise, naming the
    parameter and the kind of class wanted."""
    path = built_in.get(value, value)
    module_name, _, class_name = path.partition(':')
    if not class_name:
        raise ValueError("%s must be one of %s or module:Class of your own, not '%s'"
                         % (parameter, ', '.join(built_in), value))
    try:
        module = importlib.import_module(module_name)
    except ImportError as err:
        raise ValueError("%s '%s': cannot import %s: %s"
                         % (parameter, value, module_name, err)) from None
    cls = getattr(module, class_name, None)
    if cls is None or not callable(getattr(cls, method, None)):
        raise ValueError("%s '%s': %s has no %s class %s (one with %s)"
                         % (parameter, value, module_name, kind, class_name, method))
    return cls
