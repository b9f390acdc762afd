-- COLMAP database layout of COLMAP main (after 4.1.1), used to build test fixtures.
-- Taken from Database::CreateTables in colmap/colmap src/colmap/scene/database_sqlite.cc (a 3.12+
-- version with rigs/frames/pose_priors), plus the two later changes from the project reference:
-- descriptors.type (4.0) and two_view_geometries.camera1/camera2 (main). The position of
-- descriptors.type was not checked against COLMAP's source; readers select columns by name.
-- PRAGMA user_version = 4010100 (major*1e6 + minor*1e4 + patch*100).
CREATE TABLE rigs   (rig_id               INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,    ref_sensor_id        INTEGER                             NOT NULL,    ref_sensor_type      INTEGER                             NOT NULL);
CREATE UNIQUE INDEX rig_ref_sensor_assignment ON    rigs(ref_sensor_id, ref_sensor_type);
CREATE TABLE rig_sensors   (rig_id               INTEGER                             NOT NULL,    sensor_id            INTEGER                             NOT NULL,    sensor_type          INTEGER                             NOT NULL,    sensor_from_rig      BLOB,FOREIGN KEY(rig_id) REFERENCES rigs(rig_id) ON DELETE CASCADE);
CREATE UNIQUE INDEX rig_sensor_assignment ON    rig_sensors(sensor_id, sensor_type);
CREATE TABLE cameras   (camera_id            INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,    model                INTEGER                             NOT NULL,    width                INTEGER                             NOT NULL,    height               INTEGER                             NOT NULL,    params               BLOB,    prior_focal_length   INTEGER                             NOT NULL);
CREATE TABLE frames   (frame_id             INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,    rig_id               INTEGER                             NOT NULL,    FOREIGN KEY(rig_id) REFERENCES rigs(rig_id) ON DELETE CASCADE);
CREATE TABLE frame_data   (frame_id             INTEGER                             NOT NULL,    data_id              INTEGER                             NOT NULL,    sensor_id            INTEGER                             NOT NULL,    sensor_type          INTEGER                             NOT NULL,    FOREIGN KEY(frame_id) REFERENCES frames(frame_id) ON DELETE CASCADE);
CREATE UNIQUE INDEX frame_sensor_assignment ON    frame_data(data_id, sensor_type);
CREATE TABLE images   (image_id   INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,    name       TEXT                                NOT NULL UNIQUE,    camera_id  INTEGER                             NOT NULL,    CONSTRAINT image_id_check CHECK(image_id >= 0 and image_id < 2147483647),    FOREIGN KEY(camera_id) REFERENCES cameras(camera_id));
CREATE UNIQUE INDEX index_name ON images(name);
CREATE TABLE pose_priors   (pose_prior_id              INTEGER  PRIMARY KEY  NOT NULL,    corr_data_id               INTEGER               NOT NULL,    corr_sensor_id             INTEGER               NOT NULL,    corr_sensor_type           INTEGER               NOT NULL,    position                   BLOB,    position_covariance        BLOB,    coordinate_system          INTEGER               NOT NULL);
CREATE TABLE keypoints   (image_id  INTEGER  PRIMARY KEY  NOT NULL,    rows      INTEGER               NOT NULL,    cols      INTEGER               NOT NULL,    data      BLOB,    FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE);
CREATE TABLE descriptors   (image_id  INTEGER  PRIMARY KEY  NOT NULL,    type      INTEGER               NOT NULL,    rows      INTEGER               NOT NULL,    cols      INTEGER               NOT NULL,    data      BLOB,    FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE);
CREATE TABLE matches   (pair_id  INTEGER  PRIMARY KEY  NOT NULL,    rows     INTEGER               NOT NULL,    cols     INTEGER               NOT NULL,    data     BLOB);
CREATE TABLE two_view_geometries   (pair_id  INTEGER  PRIMARY KEY  NOT NULL,    rows     INTEGER               NOT NULL,    cols     INTEGER               NOT NULL,    data     BLOB,    config   INTEGER               NOT NULL,    F        BLOB,    E        BLOB,    H        BLOB,    qvec     BLOB,    tvec     BLOB,    camera1  BLOB,    camera2  BLOB);
PRAGMA user_version = 4010100;
