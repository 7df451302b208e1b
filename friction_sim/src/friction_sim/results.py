"""A run's results as numpy arrays, from a results folder (`friction_run --out`, a sweep's runs) or from
a bag of the rig (`rig.launch record:=true`, `rosbag record`): the one place where the columns of the
rig's tables are named.

    from friction_sim import results
    run = results.load("results/experiment/latest/run.bag")   # or a friction_run results folder
    run.events["shear_ratio"], run.events["length_ratio"]      # one value per slip event
    run.loading["time_s"], run.loading["shear_force_N"]        # the load cells (a folder: loading.csv)
    run.slip_map.slip_velocity                                 # (frames, nodes), the camera; bags only
    run.gauges.sigma_xx                                        # (profiles, gauges), the strain gauges
    run.events.to_dataframe()                                  # a pandas DataFrame, where pandas is installed

The column names and units are docs/analysis.md's ("Output files").
"""
import collections
import csv
import math
import os
import threading

import numpy as np

# friction_run's events.csv columns (results_io.cpp, writeEventsCsv), which event_row fills from a bag.
EVENT_COLUMNS = ["index", "onset_time_s", "end_time_s", "onset_shear_force_N", "onset_normal_force_N", "shear_ratio",
                 "end_shear_force_N", "nucleation_x_m", "slip_min_x_m", "slip_max_x_m", "rupture_length_m",
                 "length_ratio", "global", "median_front_speed_m_s", "front_speed_over_c_s", "front_speed_over_c_r",
                 "front_fits_left_out", "mean_shear_force_N", "mean_normal_force_N", "mean_shear_ratio",
                 "peak_shear_force_N", "peak_shear_ratio", "mean_slip_m", "unfinished"]

# The slip events of a bag: the simulator's or the precursor detector's, by topic under the rig's namespace.
EVENT_SOURCES = {"simulator": "slip_events", "detector": "precursor_detector/slip_events"}

# The CSV files of a results folder and the attribute each is loaded as.
FOLDER_TABLES = {"events": "events.csv", "loading": "loading.csv", "event_nodes": "event_nodes.csv",
                 "stresses": "stresses.csv"}


class Table:
    """Columns of one length, by name and in order, each a numpy array (numbers as float or int, text as
    str)."""

    def __init__(self, columns):
        self._columns = collections.OrderedDict((name, np.asarray(values)) for name, values in columns.items())
        lengths = {len(values) for values in self._columns.values()}
        if len(lengths) > 1:
            raise ValueError("columns of different lengths: %s" % sorted(lengths))

    @property
    def names(self):
        return list(self._columns)

    def __getitem__(self, name):
        return self._columns[name]

    def __contains__(self, name):
        return name in self._columns

    def __len__(self):
        return len(next(iter(self._columns.values()))) if self._columns else 0

    def to_dataframe(self):
        """A pandas DataFrame of the columns (ImportError where pandas is not installed)."""
        import pandas
        return pandas.DataFrame(self._columns)


SlipMap = collections.namedtuple("SlipMap", "time x slip_velocity")
SlipMap.__doc__ = """The interface camera: frame times (s), node positions x (m), slip velocity (m/s) per frame
and node."""
GaugeProfiles = collections.namedtuple("GaugeProfiles", "time x sigma_xx sigma_zz tau_xz")
GaugeProfiles.__doc__ = """Strain-gauge profiles: times (s), gauge positions x (m), and per profile and gauge the
stresses (Pa, tension positive)."""
Run = collections.namedtuple("Run", "events loading slip_map gauges event_nodes stresses scene")
Run.__doc__ = """A run's results; what its source does not hold is None (a folder has no slip map, a bag no
event_nodes or stresses tables). scene: the scene YAML as run ("" if not recorded)."""


# The columns of the rig's tables that count things; every other number is a float, whatever its digits
# (friction_run writes 1920 for 1920.0).
INTEGER_COLUMNS = {"index", "event", "node", "global", "unfinished", "front_fits_left_out", "sliding_nodes"}


def _column(name, texts):
    """A column's text cells: ints for INTEGER_COLUMNS, floats ("nan" included) for the rest and for a
    counting column with a missing ("nan") cell, str where a cell is not a number (phase, command)."""
    kinds = (int, float) if name in INTEGER_COLUMNS else (float,)
    for kind in kinds:
        try:
            return np.array([kind(t) for t in texts], dtype=kind)
        except ValueError:
            pass
    return np.array(texts, dtype=str)


def read_csv(path):
    """A CSV file with a header row as a Table."""
    with open(path, newline="") as handle:
        rows = list(csv.reader(handle))
    if not rows:
        raise ValueError("%s is empty: a results table has a header row" % path)
    header, body = rows[0], rows[1:]
    for line, row in enumerate(body, start=2):
        if len(row) != len(header):
            raise ValueError("%s line %d: %d cells, the header has %d (a run ended while writing it?)"
                             % (path, line, len(row), len(header)))
    return Table(collections.OrderedDict((name, _column(name, [row[i] for row in body]))
                                         for i, name in enumerate(header)))


def load_folder(folder):
    """The Run of a results folder; its gauge profiles are those stresses.csv holds, at each event's onset
    and end."""
    tables = {name: read_csv(os.path.join(folder, file)) if os.path.exists(os.path.join(folder, file)) else None
              for name, file in FOLDER_TABLES.items()}
    if tables["events"] is None:
        raise FileNotFoundError("%s holds no events.csv: not a results folder" % folder)
    scene = ""
    if os.path.exists(os.path.join(folder, "scene.yaml")):
        with open(os.path.join(folder, "scene.yaml")) as handle:
            scene = handle.read()
    return Run(scene=scene, slip_map=None, gauges=_gauges_from_stresses(tables["stresses"]), **tables)


def _gauges_from_stresses(stresses):
    """stresses.csv's gauge columns as profiles, one per (event, phase) in the file's order."""
    if stresses is None or len(stresses) == 0 or "gauge_sigma_xx_Pa" not in stresses:
        return None
    keys = list(zip(stresses["event"], stresses["phase"]))
    profiles = list(dict.fromkeys(keys))
    rows = [np.array([k == profile for k in keys]) for profile in profiles]
    return GaugeProfiles(time=np.array([stresses["time_s"][r][0] for r in rows]), x=stresses["x_m"][rows[0]],
                         sigma_xx=np.array([stresses["gauge_sigma_xx_Pa"][r] for r in rows]),
                         sigma_zz=np.array([stresses["gauge_sigma_zz_Pa"][r] for r in rows]),
                         tau_xz=np.array([stresses["gauge_tau_xz_Pa"][r] for r in rows]))


def load(path, namespace=None, event_source="simulator"):
    """The Run of a results folder or of a bag (the rig in `namespace`, None: the bag's only rig; the
    slip events of the simulator or of the precursor detector)."""
    if os.path.isdir(path):
        return load_folder(path)
    recording = read_bag(path, namespace, event_source, gauges=True)
    frames = recording.frames
    return Run(events=event_table(recording.events), loading=loading_table(recording.loading),
               slip_map=SlipMap(np.array([f[0] for f in frames]), np.array(frames[0][1]),
                                np.array([f[2] for f in frames])) if frames else None,
               gauges=recording.gauges, event_nodes=None, stresses=None, scene=recording.scene)


def loading_table(readings):
    """A bag's load-cell readings, (t, F_X, F_Z) each, as loading.csv's columns of them."""
    loading = np.array(readings, dtype=float).reshape(-1, 3)
    return Table(collections.OrderedDict([("time_s", loading[:, 0]), ("shear_force_N", loading[:, 1]),
                                          ("normal_force_N", loading[:, 2])]))


class BagError(Exception):
    """A bag that cannot be read, or holds no rig's load cells or slip events; the message says why."""


RigTopics = collections.namedtuple("RigTopics", "load_cells interface slip_events scene applied_commands stage_state "
                                                "strain_gauges")
Recording = collections.namedtuple("Recording",
                                   "loading events frames scene commands commands_recorded resets missing gauges")
Recording.__doc__ = """A bag's rig as recorded: load cells (t, F_X, F_Z), slip events and applied commands (the
messages), interface frames (t, positions, slip velocities, µ_s), the scene as run, whether the bag has the
commands' topic, the resets it spans, what a partial bag lacks (phrases), and the gauge profiles (or None)."""


def rig_topics(namespace, event_source):
    """The rig's topics under `namespace`, the slip events of `event_source`."""
    prefix = "/" + namespace.strip("/") + "/" if namespace.strip("/") else "/"
    return RigTopics(prefix + "load_cells", prefix + "interface", prefix + EVENT_SOURCES[event_source],
                     prefix + "scene", prefix + "applied_commands", prefix + "stage_state", prefix + "strain_gauges")


def rig_namespace(path, recorded):
    """The namespace of the bag's one rig (the one whose load cells it holds)."""
    namespaces = sorted(topic[:-len("load_cells")] for topic, info in recorded.items()
                        if topic.endswith("/load_cells") and info.msg_type == "geometry_msgs/WrenchStamped")
    if not namespaces:
        raise BagError("%s holds no rig's load cells (geometry_msgs/WrenchStamped on NS/load_cells); its topics: %s"
                       % (path, " ".join(sorted(recorded))))
    if len(namespaces) > 1:
        raise BagError("%s holds several rigs; choose one (rig_report --ns, results.load's namespace): %s"
                       % (path, " | ".join(namespaces)))
    return namespaces[0]


def read_bag(path, namespace=None, event_source="simulator", gauges=False):
    """The Recording of the rig in `namespace` (None: the bag's only rig); its gauge profiles only if
    `gauges`. BagError when the bag cannot be read or lacks the load cells or the slip events."""
    import rosbag
    loading, events, frames, commands, resets_seen, frame_indices, profiles = [], [], [], [], [], [], []
    scene = ""
    try:
        bag = rosbag.Bag(path)
    except OSError as error:
        raise BagError("cannot read the bag %s: %s" % (path, error.strerror))
    except rosbag.ROSBagException as error:
        raise BagError("cannot read the bag %s: %s" % (path, error))
    with bag:
        recorded = bag.get_type_and_topic_info().topics
        topics = rig_topics(namespace or rig_namespace(path, recorded), event_source)
        for needed in [topics.load_cells, topics.slip_events]:
            if needed not in recorded:
                raise BagError("%s holds no %s; its topics: %s" % (path, needed, " ".join(sorted(recorded))))
        wanted = [t for t in topics if gauges or t != topics.strain_gauges]
        for topic, msg, _ in bag.read_messages(topics=wanted):
            if topic == topics.scene:
                scene = msg.data
            elif topic == topics.load_cells:
                # F_Z presses down: force.z = -F_Z (bags recorded before 2026-11-25 hold +F_Z).
                loading.append((msg.header.stamp.to_sec(), msg.wrench.force.x, abs(msg.wrench.force.z)))
            elif topic == topics.slip_events:
                events.append(msg)
            elif topic == topics.applied_commands:
                commands.append(msg)
            elif topic == topics.stage_state:
                resets_seen.append(getattr(msg, "resets", 0))
            elif topic == topics.strain_gauges:
                profiles.append(msg)
            else:
                # Bags recorded before the frames carried µ_s have none.
                frames.append((msg.header.stamp.to_sec(), list(msg.position), list(msg.slip_velocity),
                               list(getattr(msg, "static_coefficient", []))))
                frame_indices.append(msg.frame_index)
    # Resets during the recording: a bag started after an earlier reset counts from there.
    resets = max(resets_seen) - min(resets_seen) if resets_seen else 0
    gauge_profiles = GaugeProfiles(
        np.array([p.header.stamp.to_sec() for p in profiles]), np.array(profiles[0].position),
        *(np.array([getattr(p, field) for p in profiles]) for field in ("sigma_xx", "sigma_zz", "tau_xz"))
    ) if profiles else None
    return Recording(loading, events, frames, scene, commands, topics.applied_commands in recorded, resets,
                     missing_parts(frame_indices, [e.index for e in events]), gauge_profiles)


def missing_parts(frame_indices, event_indices):
    """What a bag recorded late or lossily lacks, one phrase per kind, from the indices the simulator
    gives its interface frames (one count over its life) and its slip events (from 0 in each run)."""
    def skipped(indices):
        return sum(b - a - 1 for a, b in zip(indices, indices[1:]) if b > a + 1)
    missing = []
    if frame_indices and frame_indices[0] != 0:
        missing.append("the interface frames before number %d (the start of the run)" % frame_indices[0])
    if skipped(frame_indices):
        missing.append("%d interface frames between the recorded ones" % skipped(frame_indices))
    if event_indices and event_indices[0] != 0:
        missing.append("the slip events before number %d" % event_indices[0])
    if skipped(event_indices):
        missing.append("%d slip events between the recorded ones" % skipped(event_indices))
    return missing


def length_ratio(e):
    """L_p/L; NaN where L is unknown (0: the detector's events on one interface node without a scene)."""
    return e.rupture_length / e.slider_length if e.slider_length > 0 else math.nan


def event_row(e):
    """A SlipEvent's columns, named and ordered as EVENT_COLUMNS; a quantity a bag recorded before events
    carried it is NaN."""
    missing = math.nan
    normal, mean_normal = e.onset_normal_force, getattr(e, "mean_normal_force", 0.0)
    median = getattr(e, "median_front_speed", missing)

    def per(value, scale):
        return value / scale if scale > 0 else missing

    return collections.OrderedDict([
        ("index", e.index), ("onset_time_s", e.onset_time), ("end_time_s", e.end_time),
        ("onset_shear_force_N", e.onset_shear_force), ("onset_normal_force_N", normal),
        ("shear_ratio", per(e.onset_shear_force, normal)), ("end_shear_force_N", e.end_shear_force),
        ("nucleation_x_m", e.nucleation_position), ("slip_min_x_m", e.slip_min_x), ("slip_max_x_m", e.slip_max_x),
        ("rupture_length_m", e.rupture_length), ("length_ratio", length_ratio(e)),
        ("global", int(e.global_event)), ("median_front_speed_m_s", median),
        ("front_speed_over_c_s", per(median, e.shear_wave_speed)),
        ("front_speed_over_c_r", per(median, e.rayleigh_speed)),
        ("front_fits_left_out", getattr(e, "front_fits_left_out", missing)),
        ("mean_shear_force_N", getattr(e, "mean_shear_force", missing)), ("mean_normal_force_N", mean_normal),
        ("mean_shear_ratio", per(getattr(e, "mean_shear_force", missing), mean_normal)),
        ("peak_shear_force_N", getattr(e, "peak_shear_force", missing)),
        ("peak_shear_ratio", per(getattr(e, "peak_shear_force", missing), normal)),
        ("mean_slip_m", getattr(e, "mean_slip", missing)), ("unfinished", int(getattr(e, "unfinished", False)))])


def event_table(events):
    """SlipEvent messages as a Table of EVENT_COLUMNS."""
    rows = [event_row(e) for e in events]
    return Table(collections.OrderedDict((name, [row[name] for row in rows]) for name in EVENT_COLUMNS))


class EventsAfterFrames:
    """Hands each slip event on only after the interface frame that closes it (the first stamped at or
    after the event's end): the simulator publishes that frame first, but across two topics ROS keeps no
    order, and `slip_events` often arrives first. Feed it every frame and every event, in arrival order:

        order = EventsAfterFrames(on_event)
        rospy.Subscriber("interface", InterfaceState, lambda f: (on_frame(f), order.frame(f)), queue_size=100000)
        rospy.Subscriber("slip_events", SlipEvent, order.event, queue_size=1000)

    At the end of a run (no frame follows an unfinished event), `flush()` hands on what is held. A stamp
    that goes back (a reset, a looped bag) hands on what is held and starts over. Safe to feed from two
    threads; `on_event` runs on the thread that fed the frame or the event that released it, in the order
    the events arrived, one at a time (it must not feed this object)."""

    def __init__(self, on_event):
        self._on_event = on_event
        self._held = []
        self._latest_frame = None
        # rospy calls each topic's callbacks on a thread of its own: frames and events come in together.
        self._lock = threading.Lock()
        # Taken before _lock is let go and held while handing on: a batch released later waits for the
        # one released before it, which another thread may still be handing on.
        self._handing_on = threading.Lock()

    def frame(self, frame):
        def release():
            ready = []
            if self._latest_frame is not None and frame.header.stamp < self._latest_frame:
                ready, self._held = self._held, []
            self._latest_frame = frame.header.stamp
            return ready + self._take_ready()
        self._release(release)

    def event(self, event):
        def release():
            self._held.append(event)
            return self._take_ready()
        self._release(release)

    def flush(self):
        def release():
            ready, self._held = self._held, []
            return ready
        self._release(release)

    def _release(self, take):
        """Hands on what `take` removes from the held events, after every batch released before it."""
        with self._lock:
            ready = take()
            self._handing_on.acquire()
        try:
            for event in ready:
                self._on_event(event)
        finally:
            self._handing_on.release()

    def _take_ready(self):
        """Removes and returns the held events whose closing frame has come (call with the lock held)."""
        if self._latest_frame is None:
            return []
        ready = [e for e in self._held if e.header.stamp <= self._latest_frame]
        self._held = [e for e in self._held if e.header.stamp > self._latest_frame]
        return ready
