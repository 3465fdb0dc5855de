#!/usr/bin/env python3
"""rostest: parameters reach the nodes as the types they read (see tests/node_params.test).

The nodes are started from here (rosrun-style, `_name:=value` or parameters set on the master
first), so each runs in a folder of the test's own and its exit status and console are seen.
"""
import glob
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest

import roslib.packages
import rospy
import rostest
import yaml
from clothwind.msg import Clip, WindEstimate, WindMeasurement
from sensor_msgs.msg import Image

WIDTH, HEIGHT = 64, 48


def node_path(name):
    found = roslib.packages.find_node("clothwind", name)
    if not found:
        raise RuntimeError("clothwind %s is not built" % name)
    return found[0]


class ClipFeed:
    """A clip buffer's inputs under namespace `ns`: 30 fps grey frames and a 4 m/s reading every
    half second, stamped now, fed until a condition holds."""

    def __init__(self, ns):
        self.images = rospy.Publisher("/%s/camera/image_raw" % ns, Image, queue_size=100)
        self.winds = rospy.Publisher("/%s/anemometer/wind" % ns, WindMeasurement, queue_size=20)
        self.frame = 0

    def connected(self, timeout):
        deadline = time.time() + timeout
        while time.time() < deadline and (self.images.get_num_connections() == 0 or
                                          self.winds.get_num_connections() == 0):
            time.sleep(0.1)
        return self.images.get_num_connections() > 0

    def until(self, done, seconds):
        """Feeds until done() or `seconds` pass; returns done()."""
        deadline = time.time() + seconds
        while time.time() < deadline and not done():
            stamp = rospy.Time.now()
            img = Image()
            img.header.stamp, img.header.frame_id = stamp, "camera_optical"
            img.height, img.width, img.encoding, img.step = HEIGHT, WIDTH, "mono8", WIDTH
            img.data = bytes([self.frame % 256]) * (WIDTH * HEIGHT)
            self.images.publish(img)
            if self.frame % 15 == 0:
                wind = WindMeasurement()
                wind.header.stamp, wind.header.frame_id = stamp, "anemometer"
                wind.speed, wind.direction, wind.valid = 4.0, 0.0, True
                self.winds.publish(wind)
            self.frame += 1
            time.sleep(1.0 / 30)
        return done()


class Spawned:
    """A node started from here, its console (stdout and stderr) kept as it comes."""

    def __init__(self, node, args, cwd=None):
        self.lines = []
        self.lock = threading.Lock()
        self.process = subprocess.Popen([node_path(node)] + args, cwd=cwd, stdout=subprocess.PIPE,
                                        stderr=subprocess.STDOUT, text=True, errors="replace")
        self.reader = threading.Thread(target=self.read, daemon=True)
        self.reader.start()

    def read(self):
        for line in self.process.stdout:
            with self.lock:
                self.lines.append(line)

    def output(self):
        with self.lock:
            return "".join(self.lines)

    def wait_for_output(self, text, timeout):
        deadline = time.time() + timeout
        while time.time() < deadline and text not in self.output() and self.process.poll() is None:
            time.sleep(0.1)
        time.sleep(0.2)  # the line's end
        return text in self.output()

    def wait(self, timeout):
        """Exit status, or None when still running after `timeout` s."""
        try:
            return self.process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            return None

    def stop(self):
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
            if self.wait(15) is None:
                self.process.kill()
                self.process.wait()
        self.reader.join(5)


def roslaunch(*args):
    return subprocess.run(["roslaunch"] + list(args), check=True, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True).stdout


class NodeParamsTest(unittest.TestCase):
    def setUp(self):
        self.spawned = []
        self.folder = tempfile.mkdtemp(prefix="clothwind_node_params_")

    def tearDown(self):
        for s in self.spawned:
            s.stop()
        shutil.rmtree(self.folder, ignore_errors=True)

    def spawn(self, node, args, cwd=None):
        s = Spawned(node, args, cwd)
        self.spawned.append(s)
        return s

    def expect_refused(self, cases, prefix):
        """Starts each (node, private parameters, message) at once as /<prefix>_<i> and expects it
        to end with status 1 and a FATAL holding the message."""
        started = []
        for i, (node, params, _) in enumerate(cases):
            name = "/%s_%d" % (prefix, i)
            for key, value in params.items():
                rospy.set_param(name + "/" + key, value)
            started.append(self.spawn(node, ["__name:=" + name.lstrip("/")], cwd=self.folder))
        for (node, params, message), s in zip(cases, started):
            status = s.wait(30)
            s.reader.join(5)
            self.assertEqual(status, 1, "%s %s did not end; it said:\n%s" % (node, params, s.output()))
            self.assertIn(message, s.output(), (node, params))
            self.assertIn("FATAL", s.output(), (node, params))

    # `rosrun clothwind clip_buffer_node _record_dir:=20261206` (and roslaunch's record_dir:=20261206
    # before its launch files said type="str") stores an int: the node read no text, left
    # record_dir empty and recorded nothing, without a word.
    def test_record_dir_given_as_an_int_is_recorded_into(self):
        node = self.spawn("clip_buffer_node", [
            "__ns:=numeric", "_record_dir:=20261206", "_num_frames:=10", "_stride:=10", "_size:=32",
            "_label_window:=2.0", "_label_delay:=0.5", "_flush_after:=1.0"], cwd=self.folder)
        feed = ClipFeed("numeric")
        self.assertTrue(feed.connected(20), node.output())
        record = os.path.join(self.folder, "20261206")
        feed.until(lambda: glob.glob(os.path.join(record, "*", "label.json")), 30)
        self.assertTrue(glob.glob(os.path.join(record, "*", "label.json")),
                        "no clip recorded into %s; node said:\n%s" % (record, node.output()))
        self.assertIn('~record_dir is set to the int 20261206, read as the text "20261206"', node.output())

    # A recording folder lost and back (a USB disk replugged and mounted again: here moved aside
    # and made anew) is reopened: the writer refused every later clip until the node restarted.
    def test_a_recording_folder_lost_and_back_is_recorded_into_again(self):
        record = os.path.join(self.folder, "rec")
        node = self.spawn("clip_buffer_node", [
            "__ns:=lost", "_record_dir:=" + record, "_num_frames:=10", "_stride:=10", "_size:=32",
            "_label_window:=2.0", "_label_delay:=0.5", "_flush_after:=1.0"], cwd=self.folder)
        feed = ClipFeed("lost")
        self.assertTrue(feed.connected(20), node.output())
        self.assertTrue(feed.until(lambda: glob.glob(os.path.join(record, "*", "label.json")), 30),
                        "no clip recorded into %s; node said:\n%s" % (record, node.output()))
        os.rename(record, record + ".old")
        os.mkdir(record)
        self.assertTrue(feed.until(lambda: glob.glob(os.path.join(record, "*", "label.json")), 40),
                        "nothing recorded into the folder made again; node said:\n%s" % node.output())
        self.assertIn("no longer the one opened", node.output())  # said (stderr; INFO is buffered)
        self.assertIn("reopening it every 10 s once it is there", node.output())

    # A wrong-typed parameter ends each node with a FATAL naming it, the type found and the one
    # expected (YAML `rate: "5"` left camera_node at 30 Hz; roscpp's param() takes its default).
    def test_a_wrong_typed_parameter_ends_the_node_naming_it(self):
        cases = [
            ("camera_node", {"source": "folder", "path": self.folder, "rate": "5"},
             '~rate is set to a string ("5"), expected a double'),
            ("clip_buffer_node", {"queue_size": 2.5}, "~queue_size is set to a double (2.5), expected an int"),
            ("wind_display_node", {"mean_window": "60"}, '~mean_window is set to a string ("60"), expected a double'),
            ("clip_report_node", {"estimates": "true"}, '~estimates is set to a string ("true"), expected a bool'),
            ("anemometer_node", {"input": "topic", "baud": 9600.0},
             "~baud is set to a double (9600), expected an int"),
            ("sdn_node", {"model": self.folder, "threads": "2"}, '~threads is set to a string ("2"), expected an int'),
        ]
        self.expect_refused(cases, "bad")

    # Values out of range end the node naming the parameter and the value given: ~roi's 10.6 was
    # rounded, [100, 50, 0] dropped x and y without a word; a USB station read with the NMEA
    # decoder refused every record and published nothing; ~rate 1e-12 ended the display naming
    # no parameter.
    def test_values_out_of_range_end_the_node_naming_them(self):
        cases = [
            ("clip_buffer_node", {"roi": [10.6, 20.0, 100.0]},
             "~roi: expected [x, y, size] in whole source pixels from 0 to 1048576, got [10.6, 20, 100]"),
            ("clip_buffer_node", {"roi": [100, 50, 0]}, "~roi: size 0 means the centred square"),
            ("clip_buffer_node", {"size": 20000}, "size must be in 8..16384 px, got 20000"),
            ("anemometer_node", {"input": "usb", "protocol": "nmea"}, "~protocol: 'nmea' cannot read ~input: usb"),
            ("wind_display_node", {"rate": 1e-12}, "~rate must be from 0.001 to 1000 Hz, got 1e-12"),
        ]
        self.expect_refused(cases, "range")

    # ~diagnostic_period out of (0, 3600] s ends each node with diagnostics naming it. diagnostic_updater
    # makes a ros::Duration of it, which throws for NaN, inf or past 2^31 s: anemometer_node,
    # camera_node and sdn_node ended in std::terminate (a core dump, no parameter named), the others
    # with "Duration is out of dual 32-bit range".
    def test_a_diagnostic_period_out_of_range_ends_the_node_naming_it(self):
        expected = "~diagnostic_period: expected a time in (0, 3600] s, got "
        cases = [
            ("anemometer_node", {"input": "topic", "diagnostic_period": 1e10}, expected + "1e+10"),
            ("anemometer_node", {"input": "topic", "diagnostic_period": float("nan")}, expected + "nan"),
            ("camera_node", {"source": "folder", "path": self.folder, "diagnostic_period": 1e10}, expected + "1e+10"),
            ("sdn_node", {"model": self.folder, "diagnostic_period": float("inf")}, expected + "inf"),
            ("clip_buffer_node", {"diagnostic_period": 1e10}, expected + "1e+10"),
            ("wind_display_node", {"diagnostic_period": 0.0}, expected + "0"),
            ("session_bag_watch_node", {"diagnostic_period": -1.0}, expected + "-1"),
        ]
        self.expect_refused(cases, "period")

    # SIGTERM (systemd, docker stop, roslaunch's escalation) ends clip_buffer as Ctrl-C does: the
    # clips still waiting for their labels are labelled and recorded, and index.json lists every
    # clip on disk (it ended on the signal, and the waiting clips were lost).
    def test_sigterm_records_the_waiting_clips(self):
        record = os.path.join(self.folder, "term")
        node = self.spawn("clip_buffer_node", [
            "__ns:=term", "_record_dir:=" + record, "_num_frames:=10", "_stride:=10", "_size:=32",
            "_label_window:=2.0", "_label_delay:=3.0", "_flush_after:=10.0", "_index_interval:=600"],
            cwd=self.folder)
        published = []
        rospy.Subscriber("/term/clips", Clip, lambda c: published.append(c.sequence), queue_size=100)
        feed = ClipFeed("term")
        self.assertTrue(feed.connected(20), node.output())
        # Clips wait 3 s after their end for late readings: some are published, some still wait.
        self.assertTrue(feed.until(lambda: len(published) >= 2, 40), node.output())
        node.process.send_signal(signal.SIGTERM)
        self.assertEqual(node.wait(30), 0, node.output())
        labels = glob.glob(os.path.join(record, "clip-*", "label.json"))
        folders = sorted(os.path.basename(os.path.dirname(p)) for p in labels)
        sequences = []
        for p in labels:
            with open(p) as f:
                sequences.append(json.load(f)["sequence"])
        # A clip recorded that was never published: one of those waiting at SIGTERM.
        self.assertGreater(max(sequences), max(published), "the waiting clips were not recorded")
        with open(os.path.join(record, "index.json")) as f:
            listed = sorted(c["name"] for c in json.load(f)["clips"])
        self.assertEqual(listed, folders)

    # The serial settings are unused by a replay (topic input) or a USB station, but a bad one in
    # the field's YAML is said there, where serial input would end on it; the node runs on.
    def test_a_bad_serial_setting_is_said_where_it_is_unused(self):
        for i, (args, said) in enumerate([
                (["_input:=topic", "_baud:=4801"], "~baud: 4801"),
                (["_input:=usb", "_parity:=mark"], "~parity: 'mark' unknown")]):
            node = self.spawn("anemometer_node", ["__name:=unused_serial_%d" % i] + args, cwd=self.folder)
            self.assertTrue(node.wait_for_output("a serial input would end on it", 20), node.output())
            self.assertIn(said, node.output())
            self.assertIsNone(node.process.poll(), "it ended:\n" + node.output())

    # The report's output files are checked at start: a mistyped folder failed only after the whole
    # replay, naming a temporary file; a plot asked for without estimates was silently not drawn.
    def test_the_report_refuses_output_paths_it_cannot_write_at_start(self):
        self.expect_refused([
            ("clip_report_node", {"summary": os.path.join(self.folder, "no-such-folder", "s.json")}, "~summary"),
            ("clip_report_node", {"summary": self.folder}, "is a folder; expected a file name"),
            ("clip_report_node", {"estimate_plot": os.path.join(self.folder, "p.png")}, "it needs ~estimates true"),
        ], "bad_report")

    # SIGTERM (systemd, docker stop, kill) ends the report as Ctrl-C does: printed and written.
    def test_the_report_writes_its_summary_on_sigterm(self):
        summary = os.path.join(self.folder, "summary.json")
        rospy.set_param("/term_report/summary", summary)
        s = self.spawn("clip_report_node", ["__name:=term_report"], cwd=self.folder)
        clips = rospy.Publisher("/clips", Clip, queue_size=1)
        deadline = time.time() + 20
        while time.time() < deadline and clips.get_num_connections() == 0:
            time.sleep(0.1)
        self.assertGreater(clips.get_num_connections(), 0, s.output())  # up and spinning
        s.process.send_signal(signal.SIGTERM)
        status = s.wait(30)
        self.assertEqual(status, 0, s.output())
        self.assertTrue(os.path.exists(summary), "no summary on SIGTERM; it said:\n%s" % s.output())

    # A plot that cannot be written when the report ends (its folder gone since the start) costs only
    # the plot: the summary is written, and the exit status says a file failed.
    def test_a_plot_that_fails_at_the_end_costs_only_the_plot(self):
        summary = os.path.join(self.folder, "summary.json")
        plots = os.path.join(self.folder, "plots")
        os.mkdir(plots)
        rospy.set_param("/late_report/summary", summary)
        rospy.set_param("/late_report/estimates", True)
        rospy.set_param("/late_report/estimate_plot", os.path.join(plots, "p.png"))
        s = self.spawn("clip_report_node", ["__name:=late_report"], cwd=self.folder)
        clips = rospy.Publisher("/clips", Clip, queue_size=1)
        deadline = time.time() + 20
        while time.time() < deadline and clips.get_num_connections() == 0:
            time.sleep(0.1)
        self.assertGreater(clips.get_num_connections(), 0, s.output())
        estimates = rospy.Publisher("/wind/estimate", WindEstimate, queue_size=5, latch=True)
        deadline = time.time() + 20
        while time.time() < deadline and estimates.get_num_connections() == 0:
            time.sleep(0.1)
        self.assertGreater(estimates.get_num_connections(), 0, s.output())
        e = WindEstimate()
        e.header.stamp = e.clip_end = rospy.Time(1700000000, 0)
        e.speed, e.speed_std, e.reference_speed = 4.0, 0.3, 4.5
        estimates.publish(e)  # an estimate to plot
        time.sleep(1.0)
        shutil.rmtree(plots)
        s.process.send_signal(signal.SIGTERM)
        status = s.wait(30)
        s.reader.join(5)
        self.assertEqual(status, 1, s.output())
        self.assertTrue(os.path.exists(summary), "the plot's failure cost the summary:\n%s" % s.output())

    # A misspelt key is named at start, not silently left to its default.
    def test_a_parameter_the_node_does_not_read_is_named(self):
        s = self.spawn("wind_display_node", ["__name:=spelt_display", "_rat:=5", "_plot_window:=30"])
        self.assertTrue(s.wait_for_output("not read", 20), s.output())
        self.assertIn("wind_display: private parameter ~rat set but not read by this node", s.output())
        self.assertNotIn("~plot_window", s.output())

    # ~diagnostic_period set out of range while a node runs: diagnostic_updater re-reads it (cached,
    # so `rosparam set` reaches it) in every force_update into a ros::Duration, which threw for 1e10:
    # wind_display_node ended with "Duration is out of dual 32-bit range", naming no parameter. Each
    # node (the three ways they publish: a wall timer, a throttle in the spin, WallDiagnostics)
    # refuses it naming it, sets it back to the period in use and goes on publishing diagnostics.
    def test_a_diagnostic_period_set_out_of_range_while_running_is_refused_and_set_back(self):
        from diagnostic_msgs.msg import DiagnosticArray
        model = os.path.join(roslib.packages.get_pkg_dir("clothwind"), "models", "sdn.pt")
        nodes = [
            ("wind_display_node", "running_display", {}),
            ("session_bag_watch_node", "running_bag_watch", {"bag_prefix": os.path.join(self.folder, "session")}),
            ("clip_buffer_node", "running_clip_buffer", {}),
            ("anemometer_node", "running_anemometer", {"input": "topic"}),
            ("sdn_node", "running_sdn", {"model": model}),
        ]
        seen = {}
        lock = threading.Lock()

        def heard(msg):
            with lock:
                for status in msg.status:
                    for _, name, _ in nodes:
                        if status.name.startswith(name + ":"):
                            seen.setdefault(name, []).append(time.time())

        sub = rospy.Subscriber("/diagnostics", DiagnosticArray, heard)
        started = []
        for node, name, params in nodes:
            for key, value in params.items():
                rospy.set_param("/%s/%s" % (name, key), value)
            started.append(self.spawn(node, ["__name:=" + name], cwd=self.folder))

        def heard_after(name, t):
            with lock:
                return any(s > t for s in seen.get(name, []))

        deadline = time.time() + 120  # sdn_node publishes once libtorch, the model and its warm-up are in
        while time.time() < deadline and not all(heard_after(name, 0) for _, name, _ in nodes):
            time.sleep(0.1)
        for (node, name, _), s in zip(nodes, started):
            self.assertTrue(heard_after(name, 0), "%s published no diagnostics; it said:\n%s" % (node, s.output()))
        for _, name, _ in nodes:
            rospy.set_param("/%s/diagnostic_period" % name, 1e10)
        changed = time.time()
        expected = "~diagnostic_period: expected a time in (0, 3600] s, got 1e+10; set back to the 1 s in use"
        for (node, name, _), s in zip(nodes, started):
            self.assertTrue(s.wait_for_output(expected, 20), "%s:\n%s" % (node, s.output()))
        time.sleep(2.5)
        for (node, name, _), s in zip(nodes, started):
            self.assertIsNone(s.process.poll(), "%s ended; it said:\n%s" % (node, s.output()))
            self.assertEqual(rospy.get_param("/%s/diagnostic_period" % name), 1.0, node)
            self.assertTrue(heard_after(name, changed + 1.0), "%s published no diagnostics since" % node)
        sub.unregister()

    # ~diagnostic_period sets how often a node publishes its diagnostics. The nodes publish on wall
    # timers of their own (a paused bag stops ROS time), which ran every second whatever it said.
    def test_the_diagnostic_period_is_kept(self):
        from diagnostic_msgs.msg import DiagnosticArray
        stamps = []
        sub = rospy.Subscriber("/diagnostics", DiagnosticArray,
                               lambda m: stamps.extend(time.time() for s in m.status if "slow_diagnostics" in s.name))
        s = self.spawn("wind_display_node", ["__name:=slow_diagnostics", "_diagnostic_period:=3.0"])
        deadline = time.time() + 30
        while time.time() < deadline and not stamps:
            time.sleep(0.1)
        self.assertTrue(stamps, s.output())
        first = stamps[0]
        time.sleep(9.5)
        sub.unregister()
        within = [t for t in stamps if t <= first + 9.0]
        # At 3 s: 0, 3, 6 and 9 s (4, one spare for a late timer); at 1 s there were 10.
        self.assertLessEqual(len(within), 5, (len(within), s.output()))
        self.assertGreaterEqual(len(within), 3, (len(within), s.output()))

    # image_transport's plugins keep their parameters under the topics a node advertises: a camera
    # node named "camera" publishes /camera/image_raw, so /camera/image_raw/compressed/... lie in its
    # private namespace (left on the master by a previous run, or set by the plugin): not misspelt.
    def test_parameters_under_an_advertised_topic_are_not_named(self):
        rospy.set_param("/camera/image_raw/compressed/jpeg_quality", 80)
        s = self.spawn("camera_node", ["__name:=camera", "_source:=folder", "_path:=" + self.folder,
                                       "_ratte:=5"])
        self.assertTrue(s.wait_for_output("not read", 20), s.output())
        self.assertIn("~ratte", s.output())
        self.assertNotIn("~image_raw", s.output())

    # The launch files hand text parameters over as text, whatever they look like, and pass each of
    # sdn.launch's settings on (monitor.launch passed only model, mean_window and output).
    def test_launch_files_pass_text_as_text_and_forward_sdn_settings(self):
        replay = yaml.safe_load(roslaunch("--dump-params", "clothwind", "replay.launch", "bag:=/x.bag",
                                          "record_dir:=20261206", "model:=20261207", "report:=true",
                                          "summary:=1", "estimate_plot:=2", "device:=cuda", "mean_window:=30",
                                          "camera_heading_frame:=enu", "end_on_angle:=15"))
        self.assertEqual(replay["/clip_buffer/record_dir"], "20261206")
        self.assertEqual(replay["/sdn/model"], "20261207")
        self.assertEqual(replay["/clip_report/summary"], "1")
        self.assertEqual(replay["/clip_report/estimate_plot"], "2")
        self.assertEqual(replay["/sdn/device"], "cuda")
        self.assertEqual(replay["/sdn/mean_window"], 30)
        self.assertEqual(replay["/sdn/camera_heading_frame"], "enu")
        self.assertEqual(replay["/sdn/end_on_angle"], 15)
        self.assertNotIn("/sdn/camera_heading", replay)  # empty: unset, not an empty text for an angle
        field = yaml.safe_load(roslaunch("--dump-params", "clothwind", "field.launch", "record_dir:=20261206"))
        self.assertEqual(field["/clip_buffer/record_dir"], "20261206")
        monitor = yaml.safe_load(roslaunch(
            "--dump-params", "clothwind", "monitor.launch", "model:=/m.pt", "sdn_threads:=3", "device:=auto",
            "sdn_queue_size:=4", "mean_window:=30", "flag_flies:=wind", "camera_heading:=1.5",
            "camera_heading_frame:=enu", "end_on_angle:=15", "fly_judge:=/j.pt"))
        for key, value in {"threads": 3, "device": "auto", "queue_size": 4, "mean_window": 30, "flag_flies": "wind",
                           "camera_heading": 1.5, "camera_heading_frame": "enu", "end_on_angle": 15,
                           "fly_judge": "/j.pt"}.items():
            self.assertEqual(monitor["/sdn/" + key], value, key)
        # rviz opens on the display's fixed frame (-f), and on the config's without one.
        self.assertIn(" -f monitor ", roslaunch("--args", "rviz", "clothwind", "monitor.launch"))
        self.assertIn(" -f wind_view ", roslaunch("--args", "rviz", "clothwind", "monitor.launch",
                                                  "fixed_frame:=wind_view"))
        self.assertNotIn(" -f ", roslaunch("--args", "rviz", "clothwind", "monitor.launch", "fixed_frame:=none"))
        none = yaml.safe_load(roslaunch("--dump-params", "clothwind", "monitor.launch", "fixed_frame:=none"))
        self.assertEqual(none["/wind_display/fixed_frame"], "")


if __name__ == "__main__":
    rospy.init_node("node_params_check")
    rostest.rosrun("clothwind", "node_params", NodeParamsTest, sys.argv)
