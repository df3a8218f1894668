// foxi solve MODEL --physics transient: the written series read back by other programs (the .pvd
// parsed as XML by Python, each .vtu by meshio), the CSV's junction temperature against the last
// step's field, Zth(t) rising from 0, the energy check in the JSON, and bad input refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "test_util.hpp"

namespace foxi {
namespace {

constexpr int kUsage = 2, kBadInput = 3;  // apps/foxi/exit_codes.hpp

TEST(TransientCli, DieOnSubstrateSeriesReadsBackInMeshio) {
  if (test::run("/usr/bin/python3 -c 'import meshio' > /dev/null 2>&1") != 0) GTEST_SKIP() << "no meshio";
  test::TempDir dir;
  const std::string out = (dir / "run.pvd").string();
  const int status = test::run_cli("solve " + test::models_dir() + "die_on_substrate.toml --physics transient --time 2s "
                                   "--steps 20 --write-every 5 -o " + out + " --json " + (dir / "r.json").string(),
                                   dir / "solve.log");
  ASSERT_EQ(status, 0) << test::read_text(dir / "solve.log");
  const std::string script = R"PY(
import csv, json, sys, xml.etree.ElementTree as ET, os
import meshio
d = sys.argv[1]
sets = ET.parse(os.path.join(d, 'run.pvd')).getroot().find('Collection').findall('DataSet')
times = [float(s.get('timestep')) for s in sets]
assert len(sets) == 5, len(sets)
assert all(abs(t - 0.5 * i) < 1e-12 for i, t in enumerate(times)), times
rows = list(csv.reader(open(os.path.join(d, 'run_junction.csv'))))
head, rows = rows[0], [[float(x) for x in r] for r in rows[1:]]
assert len(rows) == 21, len(rows)
tj, zth = head.index('Tj[die]_K'), head.index('Zth[die]_K/W')
last = meshio.read(os.path.join(d, sets[-1].get('file')))
tmax = float(last.point_data['temperature'].max())
assert abs(tmax - rows[-1][tj]) <= 1e-6 * tmax, (tmax, rows[-1][tj])
first = meshio.read(os.path.join(d, sets[0].get('file')))
assert abs(float(first.point_data['temperature'].max()) - 300) < 1e-6
z = [r[zth] for r in rows]
assert z[0] == 0 and all(b > a for a, b in zip(z, z[1:])), z
assert abs(z[-1] - (rows[-1][tj] - 300) / 0.5) < 1e-6 * z[-1]
j = json.load(open(os.path.join(d, 'r.json')))
assert j['status'] == 'ok' and j['physics'] == 'transient', j['status']
assert any(c['name'] == 'energy' and c['passed'] for c in j['checks'])
print('ok', z[-1])
)PY";
  test::write_text(dir / "check.py", script);
  ASSERT_EQ(test::run("/usr/bin/python3 " + (dir / "check.py").string() + " " + dir.path().string(), dir / "py.log"), 0)
      << test::read_text(dir / "py.log");
}

TEST(TransientCli, BadPowerTableRowIsNamedWithFileAndLine) {
  test::TempDir dir;
  test::write_text(dir / "p.csv", "time_s,power_W\n0,1\n0.5,oops\n");
  const int status = test::run_cli("solve " + test::models_dir() + "die_on_substrate.toml --physics transient --time 1s "
                                   "--steps 4 --power die=table:" + (dir / "p.csv").string() + " -o " +
                                   (dir / "r.pvd").string(), dir / "log");
  EXPECT_EQ(status, kBadInput);
  const std::string log = test::read_text(dir / "log");
  EXPECT_NE(log.find("p.csv:3"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(dir / "r.pvd"));
}

TEST(TransientCli, MissingTimeIsAUsageError) {
  test::TempDir dir;
  EXPECT_EQ(test::run_cli("solve " + test::models_dir() + "die_on_substrate.toml --physics transient --steps 4 -o " +
                              (dir / "r.pvd").string(), dir / "log"),
            kUsage);
}

}  // namespace
}  // namespace foxi
