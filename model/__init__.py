"""The nodal (RC network) building model: building files, weather, the network and its integration.

Modules import nothing heavy at package level: the FMU bundles the physics modules
(`building`, `building_file`, `discretise`, `network`, `integrate`, `errors`) and runs them with
numpy and scipy only.
"""
