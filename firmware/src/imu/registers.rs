//! ICM-42688-P user-bank-0 register addresses and the field values the driver writes.
//!
//! Addresses are the datasheet's (register bank 0 unless marked). Every register is 8 bits;
//! 16-bit sensor words are two registers, high byte (`…1`) first: big-endian, the reset
//! setting of `INTF_CONFIG0.SENSOR_DATA_ENDIAN`.
//!
//! SPI framing: the first byte of a transaction is the address with bit 7 set for a read
//! ([`SPI_READ`]) and clear for a write; every following byte reads or writes the next
//! address (auto-increment), so one transaction reads the whole sensor block.

/// Bit 7 of the address byte: set = read, clear = write.
pub const SPI_READ: u8 = 0x80;

/// DEVICE_CONFIG: bit 0 SOFT_RESET_CONFIG (write 1: reset all registers; wait 1 ms).
pub const DEVICE_CONFIG: u8 = 0x11;
/// INT_CONFIG: INT1/INT2 pin mode (pulsed/latched), drive (open-drain/push-pull), polarity.
pub const INT_CONFIG: u8 = 0x14;
/// TEMP_DATA1: temperature, high byte (°C = raw / 132.48 + 25).
pub const TEMP_DATA1: u8 = 0x1D;
/// TEMP_DATA0: temperature, low byte.
pub const TEMP_DATA0: u8 = 0x1E;
/// ACCEL_DATA_X1: accelerometer X, high byte (sensor axes).
pub const ACCEL_DATA_X1: u8 = 0x1F;
/// ACCEL_DATA_X0: accelerometer X, low byte.
pub const ACCEL_DATA_X0: u8 = 0x20;
/// ACCEL_DATA_Y1: accelerometer Y, high byte.
pub const ACCEL_DATA_Y1: u8 = 0x21;
/// ACCEL_DATA_Y0: accelerometer Y, low byte.
pub const ACCEL_DATA_Y0: u8 = 0x22;
/// ACCEL_DATA_Z1: accelerometer Z, high byte.
pub const ACCEL_DATA_Z1: u8 = 0x23;
/// ACCEL_DATA_Z0: accelerometer Z, low byte.
pub const ACCEL_DATA_Z0: u8 = 0x24;
/// GYRO_DATA_X1: gyroscope X, high byte (sensor axes).
pub const GYRO_DATA_X1: u8 = 0x25;
/// GYRO_DATA_X0: gyroscope X, low byte.
pub const GYRO_DATA_X0: u8 = 0x26;
/// GYRO_DATA_Y1: gyroscope Y, high byte.
pub const GYRO_DATA_Y1: u8 = 0x27;
/// GYRO_DATA_Y0: gyroscope Y, low byte.
pub const GYRO_DATA_Y0: u8 = 0x28;
/// GYRO_DATA_Z1: gyroscope Z, high byte.
pub const GYRO_DATA_Z1: u8 = 0x29;
/// GYRO_DATA_Z0: gyroscope Z, low byte (last byte of the sensor block).
pub const GYRO_DATA_Z0: u8 = 0x2A;
/// INT_STATUS: interrupt status, every bit cleared by reading the register.
pub const INT_STATUS: u8 = 0x2D;
/// INTF_CONFIG0: data endianness (reset 0x30: big-endian sensor data and FIFO count).
pub const INTF_CONFIG0: u8 = 0x4C;
/// INTF_CONFIG1: clock selection (reset 0x91).
pub const INTF_CONFIG1: u8 = 0x4D;
/// PWR_MGMT0: bit 5 TEMP_DIS, bits 3:2 GYRO_MODE, bits 1:0 ACCEL_MODE.
pub const PWR_MGMT0: u8 = 0x4E;
/// GYRO_CONFIG0: bits 7:5 GYRO_FS_SEL, bits 3:0 GYRO_ODR.
pub const GYRO_CONFIG0: u8 = 0x4F;
/// ACCEL_CONFIG0: bits 7:5 ACCEL_FS_SEL, bits 3:0 ACCEL_ODR.
pub const ACCEL_CONFIG0: u8 = 0x50;
/// GYRO_CONFIG1: gyro UI filter order and DEC2 filter order (reset 0x16, left as is).
pub const GYRO_CONFIG1: u8 = 0x51;
/// GYRO_ACCEL_CONFIG0: bits 7:4 ACCEL_UI_FILT_BW, bits 3:0 GYRO_UI_FILT_BW.
pub const GYRO_ACCEL_CONFIG0: u8 = 0x52;
/// ACCEL_CONFIG1: accel UI filter order (reset 0x0D, left as is).
pub const ACCEL_CONFIG1: u8 = 0x53;
/// INT_CONFIG1: bit 4 INT_ASYNC_RESET (reset 1; must be 0 for the INT pins to work).
pub const INT_CONFIG1: u8 = 0x64;
/// INT_SOURCE0: which events drive INT1 (bit 3 UI_DRDY_INT1_EN).
pub const INT_SOURCE0: u8 = 0x65;
/// WHO_AM_I: device identity, [`WHO_AM_I_VALUE`].
pub const WHO_AM_I: u8 = 0x75;
/// REG_BANK_SEL: bits 2:0 select the register bank (present in every bank).
pub const REG_BANK_SEL: u8 = 0x76;

/// WHO_AM_I of the ICM-42688-P.
pub const WHO_AM_I_VALUE: u8 = 0x47;

/// DEVICE_CONFIG.SOFT_RESET_CONFIG: reset every register to its default; self-clearing.
pub const DEVICE_CONFIG_SOFT_RESET: u8 = 1 << 0;

/// INT_STATUS.DATA_RDY_INT: a new sample is in the data registers.
pub const INT_STATUS_DATA_RDY: u8 = 1 << 3;
/// INT_STATUS.RESET_DONE_INT: set after power-on or soft reset.
pub const INT_STATUS_RESET_DONE: u8 = 1 << 4;

/// PWR_MGMT0.TEMP_DIS: 1 turns the temperature sensor off.
pub const PWR_MGMT0_TEMP_DIS: u8 = 1 << 5;
/// PWR_MGMT0.GYRO_MODE field (bits 3:2): 00 off, 01 standby, 11 low-noise.
pub const PWR_MGMT0_GYRO_MODE_MASK: u8 = 0b11 << 2;
/// PWR_MGMT0.GYRO_MODE = 11, low-noise mode.
pub const PWR_MGMT0_GYRO_LN: u8 = 0b11 << 2;
/// PWR_MGMT0.ACCEL_MODE field (bits 1:0): 00/01 off, 10 low-power, 11 low-noise.
pub const PWR_MGMT0_ACCEL_MODE_MASK: u8 = 0b11;
/// PWR_MGMT0.ACCEL_MODE = 11, low-noise mode.
pub const PWR_MGMT0_ACCEL_LN: u8 = 0b11;
/// PWR_MGMT0 with gyro and accel in low-noise mode, temperature sensor on: 0x0F.
pub const PWR_MGMT0_SENSORS_LN: u8 = PWR_MGMT0_GYRO_LN | PWR_MGMT0_ACCEL_LN;

/// Position of the FS_SEL field in GYRO_CONFIG0 / ACCEL_CONFIG0 (bits 7:5).
pub const FS_SEL_SHIFT: u8 = 5;
/// The ODR field of GYRO_CONFIG0 / ACCEL_CONFIG0 (bits 3:0).
pub const ODR_MASK: u8 = 0x0F;
/// GYRO_FS_SEL = 000: ±2000 °/s; each step up halves the range (001 ±1000 … 111 ±15.625).
pub const GYRO_FS_2000_DPS: u8 = 0b000 << FS_SEL_SHIFT;
/// ACCEL_FS_SEL = 000: ±16 g; 001 ±8 g, 010 ±4 g, 011 ±2 g.
pub const ACCEL_FS_16_G: u8 = 0b000 << FS_SEL_SHIFT;
/// ODR code 0110: 1 kHz (codes: 0001 32 kHz, 0010 16 kHz, 0011 8 kHz, 0100 4 kHz,
/// 0101 2 kHz, 0110 1 kHz, 0111 200 Hz, 1000 100 Hz, 1001 50 Hz, 1010 25 Hz,
/// 1011 12.5 Hz, 1100 6.25 Hz, 1101 3.125 Hz, 1110 1.5625 Hz, 1111 500 Hz).
pub const ODR_1_KHZ: u8 = 0b0110;

/// UI filter bandwidth code 1 (low-noise mode): max(400 Hz, ODR)/4, 250 Hz at 1 kHz.
pub const UI_FILT_BW_ODR_DIV_4: u8 = 1;
/// UI filter bandwidth code 4 (low-noise mode): max(400 Hz, ODR)/10, 100 Hz at 1 kHz.
pub const UI_FILT_BW_ODR_DIV_10: u8 = 4;
/// Position of ACCEL_UI_FILT_BW in GYRO_ACCEL_CONFIG0 (bits 7:4; gyro in bits 3:0).
pub const ACCEL_UI_FILT_BW_SHIFT: u8 = 4;

/// INT_CONFIG.INT1_POLARITY: 1 = active high.
pub const INT_CONFIG_INT1_ACTIVE_HIGH: u8 = 1 << 0;
/// INT_CONFIG.INT1_DRIVE_CIRCUIT: 1 = push-pull (0 open-drain).
pub const INT_CONFIG_INT1_PUSH_PULL: u8 = 1 << 1;
/// INT_CONFIG.INT1_MODE: 1 = latched until INT_STATUS is read (0 = 100 µs pulse).
pub const INT_CONFIG_INT1_LATCHED: u8 = 1 << 2;
/// INT_CONFIG1.INT_ASYNC_RESET: reset value 1; the datasheet requires 0 for INT pins.
pub const INT_CONFIG1_INT_ASYNC_RESET: u8 = 1 << 4;
/// INT_SOURCE0.UI_DRDY_INT1_EN: data-ready drives INT1.
pub const INT_SOURCE0_UI_DRDY_INT1_EN: u8 = 1 << 3;

/// Length of the sensor block TEMP_DATA1 ..= GYRO_DATA_Z0 read in one burst: 14 bytes.
pub const SENSOR_BLOCK_LEN: usize = (GYRO_DATA_Z0 - TEMP_DATA1) as usize + 1;

/// Raw value of a data register pair whose sensor is off or has no sample yet.
pub const DATA_INVALID: i16 = i16::MIN;
