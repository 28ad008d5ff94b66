"""Every default value in one place (python-control style).

Change a default here and every CLI option, function and app widget follows.
"""

from pathlib import Path

from . import constants

#: Store file used when none is given.
STORE_PATH = Path("pid_store.h5")
#: Seconds a writer waits for the store's write lock before giving up with a StoreError.
STORE_LOCK_TIMEOUT_S = 60.0
#: Largest store, bytes, whose working copy is changed in memory (HDF5 never writes to disk, so
#: a full disk is one line of Python's); a larger one is copied to disk and changed there, as
#: holding it in memory made every commit of a store of long records need its size in RAM
#: (10 GB for ~25 ten-minute records).
STORE_IN_MEMORY_MAX_BYTES = 256 * 2**20
#: Age, s, past which the next write of a file removes a temporary file of that file
#: (``.<name>.<16 hex>.tmp``), and the next ``--out`` of a report's or calibration's folder its
#: build folder (``.<name>.<16 hex>.tmpdir``), that one killed outright left beside it: a live
#: writer's is younger, as its writes set its time (an export takes seconds to minutes), and no
#: lock tells a live writer's apart from a dead one's beside an exported file.
STALE_TEMPORARY_FILE_AGE_S = 24 * 3600.0

# --- Measurement (Eq. 11) -------------------------------------------------------------------
#: Number of drive harmonics fitted (1 = fundamental only). Harmonics above Nyquist are dropped.
N_HARMONICS = 5
#: Fewest whole drive periods accepted in a record.
MIN_PERIODS = 10
#: Longest velocity (vibrometer) delay accepted, in drive periods: real output delays are tens of
#: µs to a few ms (under 4 periods up to ~2 kHz); longer is a unit slip.
MAX_VELOCITY_DELAY_PERIODS = 4
#: Shortest velocity delay taken without a note, s: an output delay under 1 µs is no
#: vibrometer's (decoders take µs to ms), and is what a delay in ms typed where µs are asked
#: gives (0.05 for 50 µs): 1000 x too small, it turns the phase by nothing while the delay
#: meant moves the loss factor by ~2 pi f tau (0.16 at 500 Hz and 50 µs).
MIN_NOTED_VELOCITY_DELAY_S = 1e-6
#: Number of blocks of whole periods for the standard error of the SDC.
N_UNCERTAINTY_BLOCKS = 8
#: Largest loss of the drive line's amplitude, as a fraction, that a drive whose phase moves
#: between the blocks of the standard error may cause before the record is refused as not
#: stationary in frequency (1 - |mean of the blocks' phasors| / mean of their amplitudes): the
#: fit of the record adds the blocks' phasors, so a sweep's acceleration comes out that much
#: low and the energy per cycle twice that (a 0.3 % sweep over 2 s at 500 Hz: 23 % and 40 %;
#: a two-tone beat's can come out high, so the message says only what was measured),
#: while the loss factor, a ratio, stays right. 2 % keeps the acceleration well inside the 5 %
#: a load case is matched by; the one real long record among the fixtures (69.5 s at 182 Hz,
#: whose generator's phase wanders) loses 1.6 %, analysed with a note
#: (:data:`DRIVE_COHERENCE_NOTED_LOSS`). Noise is judged apart
#: (:data:`DRIVE_PHASE_NOISE_FACTOR`).
DRIVE_COHERENCE_MAX_LOSS = 0.02
#: Loss of the drive line's amplitude (:data:`DRIVE_COHERENCE_MAX_LOSS`) above which the result
#: says it: 0.1 % of acceleration, 0.2 % of energy per cycle.
DRIVE_COHERENCE_NOTED_LOSS = 1e-3
#: A loss of the drive line's coherence (:data:`DRIVE_COHERENCE_NOTED_LOSS`) is only the drive's
#: where it exceeds this many times the median of the blocks' relative phasor variance from
#: noise (their residual variance over its degrees of freedom, times the fit's variance factor
#: of the fundamental): noise makes a loss of about a quarter of that variance times
#: chi^2(7)/8, so 10 leaves a margin of 40 that 8 blocks' scatter of it does not reach; a
#: sweep's loss does not shrink with it.
DRIVE_PHASE_NOISE_FACTOR = 10.0
#: Fewest degrees of freedom (samples less the fit's 2H + 2 parameters) the blocks' residuals
#: must hold for the drive's phase to be judged against their noise
#: (:data:`DRIVE_PHASE_NOISE_FACTOR`); fewer, and the check says nothing. Each block's noise
#: estimate is chi^2(nu)/nu of the truth: with nu = 1 the median of 8 falls under a tenth of the
#: loss noise makes in 2e-3 of records (a steady drive refused), with 2 in 6e-6, with 4 under
#: 1e-6 (2 million draws of that model).
DRIVE_PHASE_MIN_DOF = 4
#: Smallest departure, as a fraction, of one block's drive-line amplitude from the median
#: block's that counts as that channel not holding its line there (a sensor dropout): one
#: block of 8 at 5 % moves the record's fit by 0.6 %. A vibrometer losing its return for 5 %
#: of a record takes 40 % of one block's amplitude.
BLOCK_AMPLITUDE_MIN_DEPARTURE = 0.05
#: A block's departure (:data:`BLOCK_AMPLITUDE_MIN_DEPARTURE`) must also exceed this many times
#: the larger of the blocks' own spread (1.4826 x their median absolute departure) and the
#: median block's noise: the DEM bed's force line moves +-5 % from block to block at 50 Hz,
#: 5 g, and 8 normal draws exceed 6 x their MAD spread in 2.6 % of records, 6 sigma of noise
#: in ~1e-8; both together with the 5 % floor keep a steady record from being flagged.
BLOCK_AMPLITUDE_SPREAD_FACTOR = 6.0
#: Fewest blocks of the standard error the amplitude check (:data:`BLOCK_AMPLITUDE_MIN_DEPARTURE`)
#: needs: a median and a spread of fewer do not tell the steady blocks.
BLOCK_AMPLITUDE_MIN_BLOCKS = 6
#: Widest angle, in degrees, of the complex power below the force's line (Re(P_c) > 0,
#: Im(P_c) <= 0) at which a refusal of a negative reactive power says the motion channel may
#: hold the wrong quantity. A motion channel holding the derivative of its quantity (an
#: acceleration under "velocity", or an inverted displacement) turns P_c by 90 degrees, from
#: 90 - d to -d, d = atan(loss factor): within 30 degrees for loss factors up to tan 30 = 0.58,
#: beyond any particle damper's. An inverted channel turns P_c to -90 - d instead, which only a
#: negative loss factor brings within 30 degrees of 0: the bound never takes an inversion for it.
QUANTITY_SLIP_MAX_PHASE_DEG = 30.0
#: Whole drive periods between the knots of the cubic spline that takes up the drift of a
#: record: a slow wander (a shaker table at 0.3-1 Hz) is not a line over a 2 s record, and one
#: trend over it leaked the rest into the harmonics (1e-4 of loss factor at 5 %); a spline
#: follows it (1e-9), and is smooth: its B-splines have spectral nulls at multiples of f/4, so
#: it takes up nothing of the harmonics, nor of the subharmonics of a bouncing bed (f/2,
#: 3f/2). 4 periods cost 0.2-1.8 % variance on the fundamental's sine part (100-10 periods);
#: 8 or 16 follow a 3.3 Hz wander 35-3000 x worse (docs/measurement.md). A record of fewer than
#: two spaces keeps one DC and linear trend.
DRIFT_KNOT_PERIODS = 4
#: A sample within this fraction of the channel's extreme value counts toward clipping detection.
CLIPPING_RELATIVE_TOLERANCE = 1e-9
#: Run of identical extreme samples that flags a channel as clipped.
CLIPPING_MIN_RUN = 4
#: A frequency hint may lie within +- this fraction of the drive line (searched with 3 FFT bins
#: more where a short record's bins are coarser).
FREQUENCY_SEARCH_RELATIVE_WIDTH = 0.05
#: The drive peak's power must exceed the median spectral power by this factor (20 dB); the
#: largest of ~1e6 white-noise bins exceeds the median by ~20 (13 dB), a drive tone by >> 1e3.
DOMINANT_PEAK_MIN_POWER_RATIO = 100.0
#: A measured reactive power Im(P_c) must exceed this many of its own standard errors (from
#: the blocks of whole periods) to be taken as a stored kinetic energy E = Im(P_c)/w: below
#: it E is not resolved (a resistive load, noise), and Re/Im would be a number of noise.
REACTIVE_POWER_MIN_STDERRS = 3.0
#: ... and this fraction of |P_c| (a record without blocks, or noise-free): a purely resistive
#: record gives Im(P_c) ~ 1e-16 |P_c| of round-off, a loss factor of 1e15 otherwise.
REACTIVE_POWER_MIN_FRACTION = 1e-8
#: Harmonics above this fraction of the Nyquist frequency are dropped from the fit.
HARMONIC_MAX_FRACTION_OF_NYQUIST = 0.9
#: Longest FFT used for the coarse drive-frequency estimate (memory bound on long records).
FREQUENCY_FFT_MAX_SAMPLES = 2**20

#: Points on one synthesised force-displacement loop (:class:`pidcore.loop.ForceDisplacementLoop`).
LOOP_POINTS = 256

# --- DEM ------------------------------------------------------------------------------------
DEM_TIME_STEP_S = 2e-6
DEM_MIN_STEPS_PER_CONTACT = 10
DEM_CELLS = 8
DEM_MIN_STEADY_CYCLES = 80
#: Most steady cycles a run takes: 10 000 is 125 x the default, 200 s simulated at 50 Hz (hours
#: of one core for a bed); beyond it is a slip (1e9 was taken: 10^7 s simulated, its ETA read
#: as minutes until the samples, 128 per cycle, outgrew memory).
DEM_MAX_STEADY_CYCLES = 10_000
DEM_MAX_OVERLAP_FRACTION = 0.05
DEM_SEED = 12345
#: Time step used when ``time_step="auto"``: min(DEM_TIME_STEP_S, t_contact / steps per contact).
DEM_TIME_STEP_MODE = "auto"
#: Normal damping at the end of a contact: "no_attraction" (no adhesion: a wall or a dry grain
#: cannot pull) or "literal" (Eq. 2 as written, slightly attractive at the end of a contact).
DEM_NORMAL_DAMPING_MODE = "no_attraction"
#: Mass in E = m_c a^2 / (2 w^2) (Eq. 10): coupon (face sheets + core) plus all particles.
DEM_VIBRATED_MASS_CONVENTION = "coupon_plus_particles"
#: Particles move with the cell when the drive starts (no start jolt, as on a real shaker).
DEM_START_PROTOCOL = "with_cell"
#: Start from a dense packing: a bed settled with friction from a random drop is loose and
#: keeps compacting under a 1 g drive for seconds (releasing potential energy, so the walls'
#: work stays 15-50 % below the dissipation and no steady state is reached); settled first
#: without friction it is as dense as gravity makes it, and 1 g beds are steady at once.
DEM_START_PACKING = "dense"
#: 100 % fill is the cell's capacity (dense drop packing), or "paper" (36 particles).
DEM_FILL_REFERENCE = "capacity"
#: Tangential speed below which Coulomb friction is scaled down linearly (no chatter at v_t->0).
DEM_FRICTION_REGULARISATION_SPEED_M_S = 1e-6
#: Tangential force model (see constants.TangentialModel). The elastic spring lets a resting
#: bed carry tangential load without creeping (regularised Coulomb friction cannot: below
#: the regularisation speed it is a viscous damper, so a loaded bed slides slowly forever).
DEM_TANGENTIAL_MODEL = "stick_slip"
#: Impact speed whose Hertz maximum overlap sets the constant tangential stiffness
#: k_t = 8 G* sqrt(R* delta_max) (Mindlin's initial stiffness at that overlap), m/s: a typical
#: impact of the Table 3 grid (a/w is 0.03-0.3 m/s at 50-100 Hz, 5-10 g). Its stuck period
#: (2.1e-5 s, acrylic) is then longer than the contact time, so it does not shorten the step.
DEM_TANGENTIAL_REFERENCE_SPEED_M_S = 0.3
#: Cycles per block for steady-state detection (block means compared).
DEM_STEADY_BLOCK_CYCLES = 10
#: Fewest batches (of block_cycles steady cycles each) a DEM run whose cells all ran one
#: motion takes a batch-means standard error from: with 3 degrees of freedom or fewer the
#: scatter of the batches is too poor an estimate to print (t_0.975,2 = 4.3), so such a run
#: keeps no standard error.
DEM_MIN_STDERR_BATCHES = 4
#: Relative spread (max - min over the largest magnitude) of a one-motion DEM run's batch means
#: at or below which they agree (a periodic steady state whose period divides the batch): a
#: cycle's dissipation is summed over up to ~1e6 steps, so rounding alone spreads it by up to
#: ~1e6 x 2.2e-16 = 2e-10; a spread under 1e-9 is rounding, not scatter, and its "error"
#: (printed "+- 0" or "+- 1e-17") would read as a measured certainty. Such a run keeps none.
DEM_BATCHES_AGREE_RTOL = 1e-9


def dem_automatic_steady_cycles(block_cycles: int = DEM_STEADY_BLOCK_CYCLES) -> int:
    """Steady-state cycles a DEM run measures where none are asked (``steady_cycles=None``):
    DEM_MIN_STEADY_CYCLES, at least one block. The one rule for the run and for telling an
    explicit count that equals it (``--cycles 80``) from another."""
    return max(DEM_MIN_STEADY_CYCLES, block_cycles)

#: Most particle-steps (steps x particles x cells) of one DEM kernel call while driving; a
#: block runs in calls of whole cycles, at least one. Ctrl-C is answered between calls (the
#: kernel runs without the GIL): a 10-cycle block of a resting bed at 50 Hz, 1 g, 8 cells of
#: 20 particles in one call (~1.8e7 particle-steps) left the user waiting up to 4 s. Purely
#: numerical: calls of whole cycles give the same bits (pidcore.dem.simulate._drive_block).
DEM_PARTICLE_STEPS_PER_CALL = 2_000_000
#: Successive block means within this relative difference (plus 2 standard errors) = steady.
DEM_STEADY_RELATIVE_TOLERANCE = 0.1
#: ... and in both blocks the walls' work matches the dissipation within this fraction (a bed
#: still compacting releases potential energy: work < dissipation for tens of cycles).
DEM_STEADY_BALANCE_TOLERANCE = 0.02
#: Largest energy balance closure error (|W_walls - dE_mech - D| / max(|W_walls|, D)) a DEM
#: run is presented without a note at [-] ("energy balance <= 1 % on every run"; the bundled
#: grid's runs close to < 0.6 %).
DEM_ENERGY_BALANCE_LIMIT = 0.01
#: An SDC that the energy a run leaves unaccounted for could move by less than this [-] is
#: said to be 0 to within it, not unsound: a drive under 1 g where the bed barely moves
#: closes its balance to 77 % of 1e-14 J (SDC 1e-7); the paper's SDCs are 0.05 - 2.
DEM_NEGLIGIBLE_SDC = 1e-4
#: Longest transient skipped before measuring regardless (then flagged not converged) ...
DEM_MAX_TRANSIENT_CYCLES = 100
#: ... and at most this much simulated time of it: a bed that never lifts off (1 g) never passes
#: the balance test; 1 s bounds the wait (100 cycles at 50 Hz would be 2 s). Resting beds keep
#: compacting for seconds; their tally includes released potential energy (stored change).
DEM_MAX_TRANSIENT_TIME_S = 1.0
#: Force samples per drive cycle kept for the virtual shaker test (interval means). The wall
#: force of a sparse bouncing bed is a train of impulses: at 64 samples per cycle harmonic 63
#: aliases onto the fundamental and moved Eq. 11 by 1.5 % (50 Hz, 5 g, 25 %); 128 keeps the
#: shaker within 0.4 % of the walls' work there.
DEM_SAMPLES_PER_CYCLE = 128
#: Largest drive displacement amplitude a/w^2 the DEM takes, m: electrodynamic shakers stroke
#: at most about +-25-50 mm, and a larger one is a unit slip (0.2 typed for 200 Hz: 5 g at
#: 0.2 Hz is 31 m) whose simulated time (cycles / f) ran for many minutes without a word.
DEM_MAX_DISPLACEMENT_AMPLITUDE_M = 0.05
#: Drive acceleration, g, above which a DEM run notes that it may be m/s^2 typed for g: Table
#: 3 spans 1-10 g, and 5 or 10 g typed in m/s^2 read 49 or 98 "g" (a stroke a shaker makes at
#: 50 Hz and above, so check_drive_stroke cannot tell). A note, not a refusal: a shaker can.
DEM_NOTE_ACCELERATION_G = 20.0
#: Largest factor by which DEM_SAMPLES_PER_CYCLE samples per drive period may shorten the
#: contacts' time step: above ~40 kHz (1 MHz typed for 1 kHz) the step shrank 100-fold and the
#: settling alone (up to DEM_MAX_SETTLE_TIME_S of simulated time) ran for hours without a word;
#: 1e300 Hz ended in an OverflowError traceback. Also the most an explicit ``time_step`` may
#: be shorter than the automatic one (1e-15 s ran for ever).
DEM_MAX_STEP_SHORTENING = 10.0
#: Settling ends when every cell's kinetic energy is below this fraction of N m g r.
DEM_SETTLE_KINETIC_FRACTION = 1e-5
#: Longest settling time before the run is refused, s.
DEM_MAX_SETTLE_TIME_S = 1.0
#: Damping constant: "eq3" (paper Eq. 3 from the stated e_n) or "calibrated" (root-found so a
#: simulated impact gives the stated e_n exactly; matters for "no_attraction", which with
#: Eq. 3 gives e = 0.72 instead of 0.70 for acrylic, 0.40 instead of 0.30).
DEM_DAMPING_COEFFICIENT = "eq3"
#: Impact speed at which "calibrated" damping matches the table's restitution, m/s.
DEM_CALIBRATION_SPEED_M_S = 0.3
#: `specimen check` names a pair whose head-on impact through the kernel gives a restitution
#: this far from the stated one [-] (no_attraction with Eq. 3: 0.902 for 0.9, 0.718 for 0.7,
#: 0.556 for 0.5, 0.40 for 0.3). The time step's own error at the grid's smallest step (10
#: steps per contact) reaches it near e = 0.7 (0.711 in literal mode): said too, calibrated
#: damping removes that as well.
RESTITUTION_NOTE_GAP = 0.01
#: `specimen check` names a pair whose head-on impact through the kernel gives a restitution
#: this far above 1 [-]: an impact that gains energy, the explicit step's error (1.0009 at
#: the grid's 10 steps per contact for e = 1, within RESTITUTION_NOTE_GAP but printed as
#: 1.001); below it the restitution prints as 1.
RESTITUTION_GAIN_NOTE = 5e-4
#: Seconds a ``--scheduler`` address is given, after dask's connect timeout
#: (``distributed.comm.timeouts.connect``, 30 s, which a scheduler still starting needs), to
#: answer as a dask.distributed scheduler before it is refused: dask waits for that answer
#: without a limit, so a port that accepts and never replies (an HTTP server reading a request
#: line) hung the sweep for ever. A scheduler answers from its event loop in milliseconds, and
#: dask itself warns when that loop stalls over 3 s (``distributed.admin.tick.limit``): 10 s
#: leaves a busy scheduler room.
DEM_SCHEDULER_ANSWER_TIMEOUT_S = 10.0

# --- Calibration (pidcore.calibrate, pidcore calibrate) -------------------------------------
#: Most design points of a calibration (``design_size``, ``--design-size``, the Calibrate
#: page's "design points"): each is one DEM run per load case. 200 is 4 x the largest default
#: (49, all twelve DEM parameters: :func:`pidcore.calibrate.surrogate.default_design_size`) and
#: 40 x the docs' 5 points; at 12 load cases it is 2400 DEM runs, 40 x the docs' 60 that take
#: 1-4 min on two cores (docs/calibration.md): one to three hours. Beyond it is a slip: 100000
#: was taken, and merely building its 500000 run requests held the app's Cancel for minutes
#: before any DEM run (each load case's Gaussian process would then invert a 100000-square
#: matrix, 80 GB).
CALIBRATION_MAX_DESIGN_SIZE = 200

# --- Coupon (paper Sect. 2, Table 2) ---------------------------------------------------------
# The DEM reads the coupon from its specimen file (pidcore/data/specimens/paper_coupon.toml,
# written from these values); these remain for the paper-table model (pidcore.model).
COUPON_SIDE_M = 0.100
COUPON_CELLS = 441
CELL_INSCRIBED_DIAMETER_M = 4.76e-3
CELL_HEIGHT_M = 25.4e-3
FACE_SHEET_THICKNESS_M = 0.25e-3
FACE_SHEET_DENSITY_KG_M3 = 2800.0
CORE_DENSITY_KG_M3 = 32.1
#: The paper's particle count per cell that it calls 100 % fill (Sect. 5.1).
PAPER_PARTICLES_PER_FULL_CELL = 36

# --- Reports / app --------------------------------------------------------------------------
APP_PORT = 8501
APP_MAX_UPLOAD_MB = 200
#: Most load cases one DEM sweep started from the app may hold (larger grids: ``pidcore dem``).
APP_MAX_DEM_CASES = 12
#: Most cells of one DEM run the app's DEM and Calibrate tabs start (the pages' bound, not
#: the library's: the library refuses only what memory cannot hold).
APP_MAX_DEM_CELLS = 64
#: Fill (packing ratio, %) of the paper's experiments (all at 50 %), which the app's fill column
#: names as an example for an upload whose name states none (never filled in for it).
APP_DEFAULT_FILL_PERCENT = 50.0
#: Folders (relative to the working folder) the app searches for specimen files: the DEM page
#: offers them, and their particle materials are materials a measurement may state.
APP_SPECIMEN_FOLDERS: tuple[Path, ...] = (Path("data_samples") / "specimens", Path("specimens"))
#: Hours since the app last used a kept specimen file (kept it from an upload, or restored it
#: for a page) within which ``pidcore specimen kept --remove`` leaves it: an open page names
#: it in its address without any record or job doing so yet, and a reload the next morning
#: should still find it. A kept file is a few kB.
KEPT_SPECIMEN_RECENT_HOURS = 24.0

# --- Compare (measured vs DEM vs paper) -----------------------------------------------------
#: A measured case sits on a DEM grid point when its frequency is within this relative
#: tolerance: the shaker controller sets the drive frequency exactly and the analysis estimates
#: it to far better than 0.1 %, so 1 % only absorbs rounding of the nominal grid values.
COMPARE_FREQUENCY_RTOL = 0.01
#: ... and its acceleration amplitude within this relative tolerance: sine control holds the
#: amplitude to a few percent of the set level (control tolerance, sensor calibration), so 5 %.
COMPARE_ACCELERATION_RTOL = 0.05
#: ... and its fill within this many percentage points (one particle of 36 is 2.8 points, so
#: 0.5 points only absorbs rounding of a stated fill such as 33.3 vs 33.33).
COMPARE_FILL_ATOL_PERCENT = 0.5
#: Particle material and drive direction assumed when a measurement states none (the paper's).
COMPARE_DEFAULT_MATERIAL = "acrylic"
COMPARE_DEFAULT_DIRECTION = "z"
#: Report formats written by ``pidcore report`` unless --format says otherwise: all of them.
REPORT_FORMATS: tuple[str, ...] = constants.REPORT_FORMATS
#: Resolution of the PNG figures of a report, dots per inch.
REPORT_FIGURE_DPI = 150
#: Last drive cycles of a DEM run's force records drawn by ``DemResult.plot``.
FIGURE_DEM_FORCE_CYCLES = 5

# --- SDC model, equivalent damper, model figures (pidcore.model, pidcore model) ---------------
#: Interpolate SDC in log10(frequency) instead of frequency.
MODEL_LOG_FREQUENCY = False
#: Which mass enters E = m_c a^2 / (2 w^2) in ``pidcore model damper`` (VibratedMassConvention).
MODEL_VIBRATED_MASS_CONVENTION = "coupon_plus_particles"
#: Particle material assumed for the particle mass of the paper's table.
MODEL_PARTICLE_MATERIAL = "acrylic"
#: Curves of the SDC-vs-acceleration figures (DEM and interpolated frequencies), Hz.
MODEL_FIGURE_FREQUENCIES_HZ = (50.0, 100.0, 250.0, 500.0, 750.0, 1000.0)
#: Curves of the SDC-vs-frequency figures (DEM and interpolated fills), %.
MODEL_FIGURE_FILLS_PERCENT = (25.0, 40.0, 50.0, 60.0, 75.0, 90.0)
