"""Every setting of the simulator, the reward and the baselines, as pydantic models (unknown keys are errors)."""
from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from .channel import HEIGHT_RANGE


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class ChannelConfig(_Strict):
    scenario: Literal["UMa-AV", "UMi-AV", "RMa-AV"] = "UMa-AV"
    carrier_ghz: float = Field(2.0, gt=0.5, le=6.0, description="carrier frequency (TR 36.777: below 6 GHz)")
    bs_height_m: float = Field(25.0, gt=0, le=50)
    shadow_corr_m: float = Field(50.0, gt=0, description="decorrelation distance of shadowing and LoS state")
    fading_db: float = Field(3.0, ge=0, le=10, description="std of the fast-fading residual left after L3 filtering")
    fading_corr_s: float = Field(0.3, gt=0, description="correlation time of that residual")


class RadioConfig(_Strict):
    bs_tx_power_dbm: float = Field(46.0, ge=0, le=60, description="total BS transmit power")
    ue_tx_power_dbm: float = Field(23.0, ge=0, le=33, description="UAV uplink transmit power")
    n_rb: int = Field(50, gt=0, le=275, description="resource blocks of the carrier (50 = 10 MHz)")
    bs_antenna_gain_db: float = Field(0.0, ge=-20, le=20, description="omni BS antenna; UAVs fly above the main lobe")
    ue_noise_figure_db: float = Field(9.0, ge=0, le=20)
    bs_noise_figure_db: float = Field(5.0, ge=0, le=20)
    ul_interference_db: float = Field(6.0, ge=0, le=30, description="uplink interference over thermal at the BS")
    load: float = Field(1.0, gt=0, le=1, description="downlink load of interfering cells (RSSI for RSRQ)")


class LayoutConfig(_Strict):
    isd_m: float = Field(500.0, gt=50, le=10_000, description="inter-site distance of the hexagonal grid")
    rings: int = Field(2, ge=1, le=5, description="rings around the centre site (2 -> 19 sites)")


class FlightConfig(_Strict):
    altitude_m: tuple[float, float] = Field((50.0, 150.0), description="uniform range of flight heights")
    speed_mps: tuple[float, float] = Field((8.0, 15.0), description="uniform range of horizontal speeds")
    duration_s: float = Field(120.0, gt=0, le=3600)
    dt_s: float = Field(0.04, gt=0, le=1, description="simulation step; TTT and time of stay are multiples of it")
    turn_every_s: float = Field(30.0, gt=0, description="mean time between random heading changes")

    @property
    def n_steps(self) -> int:
        """Simulation steps in one flight."""
        return int(round(self.duration_s / self.dt_s))


class BufferConfig(_Strict):
    packet_rate_hz: float = Field(300.0, ge=0, description="Poisson arrival rate of data packets")
    data_packet_bits: float = Field(12_000.0, gt=0, description="F_d")
    control_packet_bits: float = Field(4_000.0, ge=0, description="F_c, added at each handover")
    rb_per_uav: int = Field(6, gt=0, description="|B|: resource blocks granted to the UAV")
    rb_bandwidth_hz: float = Field(180e3, gt=0, description="W_s")
    q_max_bits: float = Field(2e6, gt=0, description="buffer size; overflow is lost data")


class HandoverConfig(_Strict):
    interruption_s: float = Field(0.04, ge=0, description="no uplink service while a handover executes")
    min_time_of_stay_s: float = Field(1.0, gt=0, description="ping-pong window: back to the previous BS sooner")
    sinr_min_db: float = Field(-5.0, description="service is available while uplink SINR is at least this")
    rsrp_threshold_dbm: float = Field(-100.0, description="RSRP below this is a violation")
    rsrq_threshold_db: float = Field(-16.0, description="RSRQ below this is a violation")


class RewardConfig(_Strict):
    """r = -w_handover*[handover] - w_buffer*q/q_max - w_rsrp*[RSRP<thr] - w_rsrq*[RSRQ<thr] (per decision)."""

    w_handover: float = Field(3.0, ge=0, description="3 measured best: 1 leaves the DQN at 12 handovers per flight")
    w_buffer: float = Field(1.0, ge=0)
    w_rsrp: float = Field(0.5, ge=0)
    w_rsrq: float = Field(0.5, ge=0)


class SimConfig(_Strict):
    channel: ChannelConfig = ChannelConfig()
    radio: RadioConfig = RadioConfig()
    layout: LayoutConfig = LayoutConfig()
    flight: FlightConfig = FlightConfig()
    buffer: BufferConfig = BufferConfig()
    handover: HandoverConfig = HandoverConfig()
    reward: RewardConfig = RewardConfig()
    decision_every: int = Field(5, ge=1, description="simulation steps per decision of a learned policy")

    @model_validator(mode="after")
    def _altitudes_in_model_range(self):
        lo, hi = HEIGHT_RANGE[self.channel.scenario]
        a, b = self.flight.altitude_m
        if not (lo < a <= b <= hi):
            raise ValueError(f"flight.altitude_m {self.flight.altitude_m} is outside {self.channel.scenario}'s "
                             f"range ({lo}, {hi}] m; choose heights in it (and low <= high)")
        s0, s1 = self.flight.speed_mps
        if not (0 <= s0 <= s1):
            raise ValueError("flight.speed_mps must be (low, high) with 0 <= low <= high")
        return self


class CHMConfig(_Strict):
    """Conventional handover: A3 event (TR 36.777 Table A.2.1-1 defaults)."""

    offset_db: float = Field(2.0, description="A3 offset: neighbour RSRP must exceed serving RSRP by this")
    ttt_s: float = Field(0.16, ge=0, description="time-to-trigger")


class SAMROConfig(_Strict):
    """Service-availability-driven MRO (see baselines.SAMRO for the rule)."""

    offset_db: float = Field(2.0, description="starting handover margin")
    ttt_s: float = Field(0.16, ge=0, description="starting time-to-trigger")
    window_s: float = Field(2.0, gt=0, description="measurement window of service availability")
    target_availability: float = Field(0.99, gt=0, le=1)
    margin_step_db: float = Field(1.0, gt=0)
    margin_range_db: tuple[float, float] = (0.0, 10.0)
