// Capture studies: a scenario plus distributions over its inputs (the target's tumble, the grasp,
// the arm's configuration, the timing, the target's mass), sampled deterministically (sample i
// depends only on the seed and i), each sample a capture and optionally a short motion after it;
// one row of outcomes per sample, and their summary. What `kdl_space study` and kdl_space.study()
// run; the engines (threads, shards, Dask) only decide where the rows are computed.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"

namespace kdl_space {

/// How one input is drawn.
struct Distribution {
  enum class Kind {
    Uniform,    ///< uniform on [a, b]
    Normal,     ///< normal, mean a, standard deviation b; truncated to [min, max] (drawn given it lies there)
    Grid,       ///< `count` evenly spaced values from a to b (a factor of the study's full grid)
    LogNormal,  ///< log-normal: median a > 0, factor b > 1 (exp of the log's standard deviation)
  };
  Kind kind = Kind::Uniform;
  double a = 0.0, b = 0.0;
  long count = 0;  ///< Grid only
  /// Normal only: the bounds it is truncated to (infinite: not truncated on that side).
  double min = -std::numeric_limits<double>::infinity(), max = std::numeric_limits<double>::infinity();
};

/// What one input of a study sets in the scenario (see docs/studies.md for the field names).
struct StudyInput {
  enum class Field {
    TargetTwist,   ///< target.twist.{vx,vy,vz,wx,wy,wz}: a component of its twist at the CoM, world
    TargetTumble,  ///< target.tumble: its angular velocity, this rate [rad/s] about a random axis
    TargetMass,    ///< target.mass [kg] (its inertia scaled with it: the same shape, denser)
    TargetGrasp,   ///< target.grasp.{x,y,z}: the grasp point moved on the target, target frame [m]
    Timing,        ///< timing: the capture this much later [s] along the target's torque-free tumble
    JointPosition, ///< robot.q.JOINT [rad or m]
    JointRate,     ///< robot.qdot.JOINT [rad/s or m/s]
    SelfMotion,    ///< robot.self_motion: this far [rad] along the redundant arm's self-motion
    ContactOffset, ///< robot.contact.offset.{x,y,z}: the hand's contact point, contact link frame [m]
    /// target.inertia.{I1,I2,I3}: a factor on one principal moment (ascending order) about the CoM
    TargetPrincipalInertia,
    TargetInertiaTilt,  ///< target.inertia.tilt: the principal axes turned this far [rad] about a random axis
    TargetTumbleCone,   ///< target.tumble_cone: the tumble's axis this far [rad] from the scenario's, random azimuth
  };
  std::string name;  ///< as in the study file ("robot.q.joint3")
  Field field = Field::TargetTwist;
  int index = 0;     ///< the component (0..5, 0..2) or the joint (model order)
  Distribution distribution;
};

/// Limits whose exceedance a study counts (unset: not checked).
struct StudyLimits {
  /// Per joint (model order) [rad/s]: after the impact and, with a motion, through it.
  std::optional<std::vector<double>> joint_rate;
  std::optional<std::vector<double>> joint_torque;  ///< per joint [N m], through the motion
  std::optional<double> base_rate;                  ///< |w| of the base after the impact [rad/s]
};

/// A heat map of one outcome over two inputs.
struct StudyHeatMap {
  std::string x, y, outcome;  ///< column names: x and y the study's grid inputs
  /// The per-grid-point aggregate drawn in each cell (one value a cell, however many samples):
  /// "mean" (default), "q95", "max", or "probability" for an exceeds.* outcome.
  std::string statistic = "mean";
};

/// A study file, read and checked.
struct Study {
  std::string file;
  std::uint64_t fingerprint = 0;  ///< of the study's, scenario's and URDFs' bytes: parts must agree
  Scenario scenario;
  std::vector<StudyInput> inputs;  ///< in file order
  std::uint64_t samples = 0;
  std::uint64_t seed = 0;
  bool latin_hypercube = false;    ///< `sampling: latin_hypercube` (else independent draws)
  double motion_duration = 0.0;    ///< [s]; 0: no motion after the capture
  double motion_output_step = 0.0; ///< [s] where the motion's peaks are read
  StudyLimits limits;
  std::string objective = "base_rate";  ///< the outcome the best (smallest) and worst samples rank by
  /// `objective: {outcome, statistic}`: the grid points (not the samples) are ranked by this
  /// aggregate of the outcome ("mean", "q95", "max"; "probability" for exceeds.*); empty: plain.
  std::string objective_statistic;
  std::optional<StudyHeatMap> heat_map;
  /// The most samples a study may ask for.
  static constexpr std::uint64_t max_samples = 1000000000ULL;
};

/// \brief The joint angles (model order) a `robot.self_motion` value s gives: the scenario's
/// capture configuration moved s [rad, joint-space arc length] along the arm's self-motion, the
/// hand's pose held (what a study's sample with that input computes; its q.JOINT columns).
/// \throws InputError "robot.self_motion: ..." for an arm with no one-parameter self-motion, or
/// one that cannot move that far (a singularity on the way).
KDL_SPACE_EXPORT std::vector<double> selfMotionJoints(const Scenario& scenario, double s);

/// \brief Reads and checks a study file (YAML or JSON): its scenario (loadScenario, relative to
/// the study's folder), each input's field and distribution, the sample count, seed, limits.
/// \throws InputError "FILE[:LINE]: FIELD: what is wrong", as loadScenario.
KDL_SPACE_EXPORT Study loadStudy(const std::string& path);

/// \brief The table's columns: sample, status, the inputs drawn (target.tumble adds its axis),
/// then the outcomes (impulse, base twist after, base_rate, joint rate jumps, energy lost, the
/// motion's peaks, the limits exceeded as 0/1).
KDL_SPACE_EXPORT std::vector<std::string> studyColumns(const Study& study);

/// \brief Computes rows of a study: one per sample, the values of studyColumns(). Owns its
/// workspaces (the capture's side, the self-motion's solver), so one per thread.
class KDL_SPACE_EXPORT StudyEvaluator {
 public:
  explicit StudyEvaluator(std::shared_ptr<const Study> study);
  ~StudyEvaluator();
  StudyEvaluator(const StudyEvaluator&) = delete;
  StudyEvaluator& operator=(const StudyEvaluator&) = delete;
  /// \brief Sample i's row into `row` (studyColumns().size() values). Never throws: a sample
  /// that cannot be computed has its status (an error code, or E_BAD_ARGUMENT for a set-up the
  /// library refused) and NaN outcomes, and failure() says why; its inputs are always filled.
  void evaluate(std::uint64_t i, double* row);
  /// \brief evaluate(), with the sample's inputs `drawn` (studyInputCount() values, in the order
  /// of the table's input columns) instead of the study's draws: a caller's own sampler (Python's
  /// `sampler=`). Its row holds them. A value outside an input's domain (a mass <= 0) fails the
  /// sample as a refused set-up does; an axis is used as given (the caller gives unit vectors).
  void evaluate(std::uint64_t i, const double* drawn, double* row);
  /// Why the last sample evaluated failed: the refusal's message (an Error's), or what could not
  /// be computed and strError(status); empty if it computed.
  const std::string& failure() const { return failure_; }
  std::size_t columns() const { return columns_; }

 private:
  struct Work;
  void sample(std::uint64_t i, const double* drawn, double* row);  ///< evaluate, but a set-up's refusal throws
  std::shared_ptr<const Study> study_;
  std::size_t columns_;
  std::unique_ptr<Work> work_;
  std::string failure_;
};

/// The number of input columns of the study's table (after sample and status): one per input,
/// four for target.tumble, target.inertia.tilt and target.tumble_cone (the value and an axis).
KDL_SPACE_EXPORT std::size_t studyInputCount(const Study& study);

/// \brief Sample i's inputs as the study draws them (its table's input columns): what
/// StudyEvaluator::evaluate(i, drawn, row) takes, for a caller that replaces some of them.
KDL_SPACE_EXPORT std::vector<double> studyDraws(const Study& study, std::uint64_t i);

/// A run of rows [begin, end) in chunks.
struct StudyChunk {
  std::uint64_t begin = 0, end = 0;
};

/// \brief The chunks of [begin, end) on the study's fixed grid of chunks (of chunk_size samples
/// from 0; the first and last cut to the range): the same whatever the engine or the threads,
/// so a run can resume from chunks written by another.
KDL_SPACE_EXPORT std::vector<StudyChunk> studyChunks(std::uint64_t begin, std::uint64_t end, std::uint64_t chunk_size);

/// The chunk size a study of `samples` uses by default (256 chunks or more, 16 to 65536 rows).
KDL_SPACE_EXPORT std::uint64_t defaultChunkSize(std::uint64_t samples);

/// The grid of chunks of rows [begin, end): chunks of chunk_size samples from 0, the first and
/// last cut to the range (the chunks studyChunks lists), generated as they are needed.
struct StudyGrid {
  std::uint64_t begin = 0, end = 0;
  std::uint64_t chunk_size = 1;  ///< 0 is taken as 1

  /// The chunks that meet [begin, end): chunk k holds rows [k c, (k + 1) c) of the whole study, cut
  /// to [begin, end) (so a shard's chunks are the whole run's, and their files the same).
  std::uint64_t count() const { return end <= begin ? 0 : (end - 1) / size() - begin / size() + 1; }
  /// The k-th chunk of count() (no overflow: its first row is below end).
  StudyChunk chunk(std::uint64_t k) const {
    const std::uint64_t from = (begin / size() + k) * size();
    return StudyChunk{from > begin ? from : begin, end - from > size() ? from + size() : end};
  }

 private:
  std::uint64_t size() const { return chunk_size ? chunk_size : 1; }
};

/// Called with each chunk finished: rows is chunk size x columns, row-major.
using StudyChunkDone = std::function<void(const StudyChunk&, const std::vector<double>& rows)>;

/// \brief Computes the chunks of `grid` on `threads` threads (0: all cores), each with its own
/// evaluator; the threads take the chunks in order from a counter, so nothing proportional to the
/// number of chunks is held (a study of 1e9 samples in chunks of 16 needs no list of chunks).
/// `skip(chunk)` (may be empty; called from the threads at once: it must be thread-safe) true leaves a chunk
/// out (e.g. one already on disk). `done(chunk, rows)` is called for each chunk as it completes,
/// one call at a time, in any order. `cancel` (may be null) set to true stops the run within a
/// sample on every thread: a chunk cut short is not handed to `done`. An exception thrown by
/// `done` or `skip` stops the run (also within a sample) and propagates.
KDL_SPACE_EXPORT void runStudy(const std::shared_ptr<const Study>& study, const StudyGrid& grid, unsigned threads,
                               const StudyChunkDone& done, const std::atomic<bool>* cancel = nullptr,
                               const std::function<bool(const StudyChunk&)>& skip = {});

/// \brief runStudy on a list of chunks (any ranges, computed in the list's order), as above.
KDL_SPACE_EXPORT void runStudy(const std::shared_ptr<const Study>& study, const std::vector<StudyChunk>& chunks,
                               unsigned threads, const StudyChunkDone& done, const std::atomic<bool>* cancel = nullptr);

/// Quantiles of one outcome over the samples that computed (status 0).
struct OutcomeSummary {
  std::string name;
  double min = 0, q05 = 0, q25 = 0, median = 0, q75 = 0, q95 = 0, max = 0, mean = 0;
};
/// One sample's inputs and the objective, for the best and worst lists.
struct SampleDigest {
  std::uint64_t sample = 0;
  double objective = 0.0;
  std::vector<std::pair<std::string, double>> inputs;
};
/// The samples of a table that failed with one status.
struct StudyFailure {
  int status = 0;                 ///< the table's status (an error code)
  std::uint64_t count = 0;        ///< samples with this status
  std::uint64_t first_sample = 0; ///< the smallest such sample index
  /// Why first_sample failed: StudyEvaluator::failure() of that sample evaluated again (sample i
  /// depends only on the seed and i, so the table's rows may come from any engine, shard or run).
  std::string message;
};

/// The aggregates of the samples at one point of the study's grid (one value of each grid input).
struct GridPointSummary {
  std::uint64_t index = 0;  ///< the grid point: sample i is at point i mod (the grid's size)
  std::vector<std::pair<std::string, double>> inputs;  ///< the grid inputs' values, in file order
  std::uint64_t count = 0, failed = 0;  ///< its samples that computed; that failed
  /// Per outcome (not exceeds.*), over the point's computed samples: the mean, the 95 %
  /// quantile (as OutcomeSummary's), the max; NaN when none computed.
  struct Outcome {
    std::string name;
    double mean = 0, q95 = 0, max = 0;
  };
  std::vector<Outcome> outcomes;
  std::vector<std::pair<std::string, double>> probabilities;  ///< per exceeds.* column
};
/// A grid point as the objective ranks it.
struct GridPointDigest {
  std::uint64_t index = 0, count = 0;
  double objective = 0.0;  ///< the objective's statistic of its outcome at this point
  std::vector<std::pair<std::string, double>> inputs;
};

/// What a whole table says.
struct StudySummary {
  std::uint64_t samples = 0, failed = 0;
  std::vector<StudyFailure> failures;  ///< one per distinct status, in the order of first_sample
  std::vector<OutcomeSummary> outcomes;
  /// Per limit column ("exceeds.base_rate", ..., "exceeds.any"): the fraction of computed
  /// samples that exceed it.
  std::vector<std::pair<std::string, double>> probabilities;
  std::vector<SampleDigest> best, worst;  ///< by the objective: up to 5 each
  /// A bound on the error of the quantiles' ranks, as a fraction of the samples that computed:
  /// 0 when they are exact (up to 65,536 such samples), else each quantile p lies between the
  /// exact order statistics of ranks p (n - 1) -+ quantile_rank_error n; at most
  /// 1/65536 + floor(log2(n / 16384)) / 16384 (under 0.001 for 1e9 samples). See docs/studies.md.
  double quantile_rank_error = 0.0;
  /// With grid inputs: the aggregates at each grid point that has samples, in the grid's order
  /// (empty without grid inputs). Each point's q95 is exact up to 65,536 computed samples there.
  std::vector<GridPointSummary> grid_points;
  /// With `objective: {outcome, statistic}`: the grid points by that statistic, up to 5 each
  /// (smallest first; largest first), ties by index; points with no computed sample left out.
  std::vector<GridPointDigest> best_grid_points, worst_grid_points;
};

/// \brief A study's summary from its rows fed a block at a time, in memory that does not grow
/// with the number of rows (about 2.2 MB per outcome at 1e9 rows: a quantile sketch each, see
/// quantile_rank_error): min, max, mean, probabilities, failures, best and worst are exact. The
/// result does not depend on how the rows were cut into blocks, nor on their order except for
/// inexact quantiles (fed in the same order, the same summary, bit for bit). Summarizers of
/// parts of a table (threads, shards) merge into the summarizer of the whole. Not thread-safe:
/// one per thread, then merge.
class KDL_SPACE_EXPORT StudySummarizer {
 public:
  explicit StudySummarizer(std::shared_ptr<const Study> study);
  ~StudySummarizer();
  StudySummarizer(StudySummarizer&&) noexcept;
  StudySummarizer& operator=(StudySummarizer&&) noexcept;
  /// `n` rows of studyColumns(study) values each, row-major, samples in any order.
  void add(const double* rows, std::size_t n);
  /// Adds another summarizer's rows (of the same study).
  void merge(const StudySummarizer& other);
  /// \brief The summary of the rows added so far; the message of each distinct failure comes
  /// from evaluating its first sample again (see summarizeStudy). May be called again later.
  StudySummary finish() const;

 private:
  struct State;
  static void gridPoints(const State& state, StudySummary& summary);
  std::unique_ptr<State> state_;
};

/// \brief The summary of a table (rows x studyColumns(study), row-major, any order of samples):
/// StudySummarizer's over the whole table. Quantiles interpolate linearly between order
/// statistics (exactly up to 65,536 computed samples, else see quantile_rank_error). The message of each distinct failure
/// comes from evaluating its first sample again in this process (one capture, and the motion
/// after it, per distinct status; nothing when every sample computed).
KDL_SPACE_EXPORT StudySummary summarizeStudy(const Study& study, const std::vector<double>& rows);

}  // namespace kdl_space
