"""The evaluation protocol as units with committed records (DESIGN §12): what the docs need
(:mod:`~seannet.protocol.design`), one unit end to end (:mod:`~seannet.protocol.unit`), its
record (:mod:`~seannet.protocol.records`), the plan and the runs under a time limit
(:mod:`~seannet.protocol.runner`) and the docs written from records alone
(:mod:`~seannet.protocol.docs`). ``seannet results plan | run | doc``."""
