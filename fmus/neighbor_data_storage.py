"""FMU `DataStorage` (instance `data`): NEIGHBOR's flash data store (256 kB = 256000 bytes)
filled at the Table 7 recording rate and emptied by the 9600-baud UHF downlink.

Wraps components.mission.data_storage.DataStorage (see its docstring for the Table 7 rate, 30.2833
B/s, against Appendix I's 29.503 B/s, k = 1000, and the exact integration). Inputs are Booleans
held over a step; every output is a state (no direct dependencies). Overflow is never silent:
bytes that do not fit are counted in `bytes_lost` and `overflow` latches true.
"""
from neighbor_fmu_support import NeighborSlave

from components.mission import data_storage


class DataStorage(NeighborSlave):
    description = ("NEIGHBOR data storage: 256 kB flash filled at the thesis Table 7 rate while recording and "
                   "downlinked at 9600 baud (1200 B/s) in ground contact; overflow counted and latched")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("capacity", data_storage.CAPACITY, "byte",
                       "Flash storage for data, > 0 (default 256 kB = 256000 bytes, k = 1000 as thesis Appendix I)")
        self.parameter("recording_rate", data_storage.RECORDING_RATE, "byte/s",
                       "Recording rate while data_recording, >= 0 (default thesis Table 7: 1817 B/min = 30.2833 B/s)")
        self.parameter("downlink_rate", data_storage.DOWNLINK_RATE, "byte/s",
                       "Downlink rate, >= 0 (default 9600 baud = 1200 B/s)")
        self.parameter("initial_storage_used", 0.0, "byte", "Bytes stored at the start, in [0, capacity]")
        self.input("data_recording", False, None, "Recording on: data stored at recording_rate", bool)
        self.input("downlink_enable", False, None, "Downlink commanded (sends only while ground_contact)", bool)
        self.input("ground_contact", False, None, "A ground station is in view", bool)
        m = lambda: self.model  # noqa: E731
        self.output("storage_used", lambda: m().storage_used, "byte", "Bytes stored, in [0, capacity]")
        self.output("storage_free", lambda: m().storage_free, "byte", "Free bytes, capacity - storage_used")
        self.output("bytes_lost", lambda: m().bytes_lost, "byte",
                    "Cumulative bytes recorded while the store was full (lost)")
        self.output("overflow", lambda: m().overflow, None, "Latched true once any byte has been lost", bool)
        self.output("downlinked", lambda: m().downlinked, "byte", "Cumulative bytes sent to the ground")

    def build_model(self):
        v = self.values
        return data_storage.DataStorage(v["capacity"], v["recording_rate"], v["downlink_rate"],
                                        v["initial_storage_used"])

    def do_step(self, current_time, step_size):
        v = self.values
        self.model.step(v["data_recording"], v["downlink_enable"], v["ground_contact"], step_size)
        return True
