"""Every public function and result property has a docstring, and every function a signature
that inspect can read."""
import inspect

import hybrid_vo
import hybrid_vo.frontend


def public_functions():
    for module in (hybrid_vo, hybrid_vo.synthetic, hybrid_vo.frontend):
        for name in dir(module):
            value = getattr(module, name)
            if not name.startswith("_") and callable(value) and not inspect.isclass(value):
                yield f"{module.__name__}.{name}", value


def test_every_function_has_a_docstring_and_a_signature():
    names = []
    for name, function in public_functions():
        names.append(name)
        assert function.__doc__ and len(function.__doc__) > 40, name
        inspect.signature(function)  # raises when there is none
    assert "hybrid_vo.estimate_relative_pose" in names and "hybrid_vo.frontend.match_image_pair" in names
    assert len(names) >= 25


def test_every_result_property_has_a_docstring():
    cls = hybrid_vo.RelativePoseEstimate
    assert cls.__doc__
    properties = [n for n, v in vars(cls).items() if isinstance(v, property)]
    assert len(properties) > 25
    for name in properties:
        assert getattr(cls, name).__doc__, name
